// Hosts web/src/worker-runtime.js in a node worker thread, the way web/src/worker.js hosts it
// in the browser: same runtime, every web/src/ops/*.js file, the node build of the module.
// Test hooks (workerData): failInits = Int32Array over a SharedArrayBuffer [failures left],
// so a test can make the first starts fail; a test-only 'crash' op simulates a wasm trap.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { parentPort, workerData } from 'node:worker_threads';
import { createWorkerRuntime } from '../../web/src/worker-runtime.js';
import { loadModule, repoDir } from './wasm_module.mjs';

const opsDir = path.join(repoDir, 'web/src/ops');
const opFiles = {};
for (const file of fs.readdirSync(opsDir).filter((f) => f.endsWith('.js')).sort()) {
  opFiles[`./ops/${file}`] = await import(pathToFileURL(path.join(opsDir, file)).href);
}
opFiles['test-hooks'] = {
  ops: {
    crash() { throw new WebAssembly.RuntimeError('unreachable executed (simulated trap)'); },
  },
};

const onMessage = createWorkerRuntime({
  loadModule: async () => {
    const failInits = workerData?.failInits;
    if (failInits && Atomics.sub(failInits, 0, 1) > 0) throw new Error('simulated start failure');
    return loadModule();
  },
  opFiles,
  post: (message, transfer) => parentPort.postMessage(message, transfer),
});
parentPort.on('message', onMessage);
