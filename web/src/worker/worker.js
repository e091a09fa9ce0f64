// The Web Worker that owns the wasm module and all geometry work. Message handling, cancel
// and the protocol live in runtime.js (shared with the node tests); this file only binds them
// to the browser: the ES-module build of the wasm and the ops list (ops/index.js).
import createMeshMorph from '@meshmorph/wasm/meshmorph_web.mjs';
import { opFiles } from './ops/index.js';
import { createWorkerRuntime } from './runtime.js';

const onMessage = createWorkerRuntime({
  loadModule: () => createMeshMorph(),
  opFiles,
  post: (message, transfer) => self.postMessage(message, transfer),
});

self.onmessage = (event) => onMessage(event.data);
