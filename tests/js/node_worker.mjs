// Hosts web/src/worker/runtime.js in a node worker thread, the way web/src/worker/worker.js
// hosts it in the browser: same runtime, the same ops list (web/src/worker/ops/index.js), the
// node build of the module.
// Test hooks (workerData): failInits = Int32Array over a SharedArrayBuffer [failures left],
// so a test can make the first starts fail; hangInits likewise makes them never answer; a
// test-only 'crash' op simulates a wasm trap.
import { parentPort, workerData } from 'node:worker_threads';
import { opFiles as pageOpFiles } from '../../web/src/worker/ops/index.js';
import { createWorkerRuntime } from '../../web/src/worker/runtime.js';
import { loadModule } from './wasm_module.mjs';

const opFiles = { ...pageOpFiles };
opFiles['test-hooks'] = {
  ops: {
    crash() { throw new WebAssembly.RuntimeError('unreachable executed (simulated trap)'); },
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
