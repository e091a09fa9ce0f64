// Hosts web/src/worker/runtime.js in a node worker thread, the way web/src/worker/worker.js
// hosts it in the browser: same runtime, the same ops list (web/src/worker/ops/index.js), the
// node build of the module.
// Test hooks (workerData): failInits = Int32Array over a SharedArrayBuffer [failures left],
// so a test can make the first starts fail; hangInits likewise makes them never answer; a
// test-only 'crash' op simulates a wasm trap, and 'block' {ms} a long step that reports no
// progress (one indivisible call, like an SVD), so a cooperative cancel cannot stop it.
import { parentPort, workerData } from 'node:worker_threads';
import { opFiles as pageOpFiles } from '../../web/src/worker/ops/index.js';
import { createWorkerRuntime } from '../../web/src/worker/runtime.js';
import { loadModule } from './wasm_module.mjs';

const opFiles = { ...pageOpFiles };
opFiles['test-hooks'] = {
  ops: {
    crash() { throw new WebAssembly.RuntimeError('unreachable executed (simulated trap)'); },
    block(ctx, options = {}) {
      const end = Date.now() + (options.ms ?? 1000);
      while (Date.now() < end) { /* busy: no progress, no cancel check */ }
      return { info: { blocked: options.ms }, buffers: {} };
    },
  },
};

const onMessage = createWorkerRuntime({
  loadModule: async () => {
    const failInits = workerData?.failInits;
    if (failInits && Atomics.sub(failInits, 0, 1) > 0) throw new Error('simulated start failure');
    const hangInits = workerData?.hangInits;
    if (hangInits && Atomics.sub(hangInits, 0, 1) > 0) await new Promise(() => {});
    return loadModule();
  },
  opFiles,
  post: (message, transfer) => parentPort.postMessage(message, transfer),
});
parentPort.on('message', onMessage);
