// Errors that cross the worker boundary. A binding result {ok:false, code, message} becomes a
// MeshMorphError carrying `code` (StatusCode names from core/common/status.h, plus the
// page-level codes below), so the UI can show the core's message and react to the code.
//
// Page-level codes: Cancelled (user pressed Cancel; same name as the core's), Aborted (a queued
// request died with a restarted worker), Crashed (the wasm module trapped; the worker is
// replaced), InitFailed (the module could not start), Internal (a bug: stray C++ exception).
export class MeshMorphError extends Error {
  constructor(code, message) {
    super(message);
    this.name = 'MeshMorphError';
    this.code = code;
  }
}

// Turns a binding result into its payload or throws.
export function unwrap(result) {
  if (!result || typeof result !== 'object') throw new MeshMorphError('Internal', 'binding returned no result');
  if (!result.ok) throw new MeshMorphError(result.code || 'Internal', result.message || 'unknown error');
  return result;
}
