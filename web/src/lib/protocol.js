// Shared by the worker and the main thread: the message protocol (STYLE.md "web/"):
//   main → worker  {type:'init', cancelFlag?} | {type:'run', id, op, options, buffers} | {type:'cancel', id}
//   worker → main  {type:'ready'} | {type:'progress', id, stage, fraction}
//                  | {type:'result', id, buffers, info} | {type:'error', id, code, message, fatal?}
// `buffers` is an object of named typed arrays; every underlying ArrayBuffer goes in the
// transfer list, both ways. `cancelFlag` is an Int32Array over a SharedArrayBuffer (only when
// the page is crossOriginIsolated): the main thread stores the id to cancel at index 0.

// Every ArrayBuffer under an object of typed arrays/ArrayBuffers. Duplicates are removed
// (postMessage throws on a buffer listed twice); SharedArrayBuffers cannot be transferred.
export function transferList(buffers) {
  const list = new Set();
  for (const value of Object.values(buffers || {})) {
    if (value instanceof ArrayBuffer) list.add(value);
    else if (ArrayBuffer.isView(value) && value.buffer instanceof ArrayBuffer) list.add(value.buffer);
  }
  return [...list];
}

// Copies of the buffers (the originals get detached by a transfer).
export function cloneBuffers(buffers) {
  const out = {};
  for (const [key, value] of Object.entries(buffers || {})) {
    out[key] = value instanceof ArrayBuffer ? value.slice(0) : ArrayBuffer.isView(value) ? value.slice() : value;
  }
  return out;
}

// The 'error' message for request `id` (null: not about one request) from a MeshMorphError;
// the client turns it back into one with toMeshMorphError (errors.js).
export function errorMessage(id, error) {
  const message = { type: 'error', id, code: error.code, message: error.message };
  if (error.fatal) message.fatal = true;
  return message;
}
