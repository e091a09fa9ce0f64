// The page's one error type and the only places error objects are made from other values.
// A binding result {ok:false, code, message} becomes a MeshMorphError carrying `code`
// (StatusCode names from core/common/status.h, plus the page-level codes below), so the UI can
// show the core's message and react to the code. The worker sends errors as {code, message}
// records (protocol.js errorMessage); the client and the UI turn them, and anything else that
// was thrown, back into MeshMorphError with toMeshMorphError.
//
// Page-level codes: Cancelled (user pressed Cancel; same name as the core's), Aborted (a queued
// request died with a restarted worker), Crashed (the wasm module trapped; the worker is
// replaced), InitFailed (the module could not start), Internal (a bug: stray C++ exception),
// OutOfMemory (the wasm heap is exhausted; both come from the bindings' guard, wasm/guard.h),
// Unsupported / IoError (the page could not read a file it was given).
export class MeshMorphError extends Error {
  // fatal: the worker that produced it cannot be used any more (a wasm trap).
  constructor(code, message, { fatal = false } = {}) {
    super(message);
    this.name = 'MeshMorphError';
    this.code = code;
    if (fatal) this.fatal = true;
  }
}

// Turns a binding result into its payload or throws.
export function unwrap(result) {
  if (!result || typeof result !== 'object') throw new MeshMorphError('Internal', 'binding returned no result');
  if (!result.ok) throw new MeshMorphError(result.code || 'Internal', result.message || 'unknown error');
  return result;
}

// A MeshMorphError for any thrown value or {code, message} record (e.g. a worker 'error'
// message). Values without a code get `fallbackCode`.
export function toMeshMorphError(value, fallbackCode = 'Internal') {
  if (value instanceof MeshMorphError) return value;
  const code = typeof value?.code === 'string' && value.code ? value.code : fallbackCode;
  const message = value?.message !== undefined ? String(value.message) : String(value);
  return new MeshMorphError(code, message, { fatal: Boolean(value?.fatal) });
}
