// The Web Worker that owns the wasm module and all geometry work. Message handling, cancel
// and the protocol live in runtime.js (shared with the node tests); this file only binds them
// to the browser: which build of the wasm module to load, and the ops list (ops/index.js).
//
// Two builds of the module (docs/web.md, "Threads"):
//  - threaded (meshmorph_web_mt, the -pthread link): needs shared memory, so only when this worker is
//    crossOriginIsolated and the client sent its URL ('init' message, threadedModuleUrl). It is
//    served beside the page as plain files (wasm-mt/…, not bundled by Vite): its pthread
//    workers load the same glue file again by URL.
//  - single-threaded (build/wasm, bundled): otherwise, and whenever the threaded one fails to
//    start (missing files, a browser without wasm threads, a pool that never comes up).
// Results are bit-identical between the two (common/threads.h).
import createSingleThreaded from '@meshmorph/wasm/meshmorph_web.mjs';
import { opFiles } from './ops/index.js';
import { createWorkerRuntime } from './runtime.js';

// How long the threaded module may take to compile and start its pthread pool.
const threadedStartMs = 20000;

function withTimeout(promise, ms, what) {
  let timer;
  return Promise.race([
    promise,
    new Promise((_, reject) => { timer = setTimeout(() => reject(new Error(`${what} did not start within ${ms / 1000} s`)), ms); }),
  ]).finally(() => clearTimeout(timer));
}

async function loadModule({ threadedModuleUrl } = {}) {
  let fallback = '';
  if (threadedModuleUrl && self.crossOriginIsolated === true) {
    try {
      const glue = await import(/* @vite-ignore */ threadedModuleUrl);
      const module = await withTimeout(glue.default({ mainScriptUrlOrBlob: threadedModuleUrl }), threadedStartMs, 'the threaded module');
      return { module };
    } catch (e) {
      fallback = `threaded module unavailable (${e?.message || e}); running on one thread`;
    }
  } else if (threadedModuleUrl) {
    fallback = 'the page is not cross-origin isolated: running on one thread';
  }
  return { module: await createSingleThreaded(), note: fallback };
}

const onMessage = createWorkerRuntime({
  loadModule,
  opFiles,
  post: (message, transfer) => self.postMessage(message, transfer),
});

self.onmessage = (event) => onMessage(event.data);
