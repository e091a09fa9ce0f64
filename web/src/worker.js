// The Web Worker that owns the wasm module and all geometry work. Message handling, cancel
// and the protocol live in worker-runtime.js (shared with the node tests); this file only
// binds them to the browser: the ES-module build of the wasm and every ops file.
//
// Ops come from web/src/ops/*.js (each exports `ops = {name: fn}`): a new module adds its file
// there and this worker picks it up at build time, without edits here.
import createMeshMorph from '@meshmorph/wasm/meshmorph_web.mjs';
import { createWorkerRuntime } from './worker-runtime.js';

const onMessage = createWorkerRuntime({
  loadModule: () => createMeshMorph(),
  opFiles: import.meta.glob('./ops/*.js', { eager: true }),
  post: (message, transfer) => self.postMessage(message, transfer),
});

self.onmessage = (event) => onMessage(event.data);
