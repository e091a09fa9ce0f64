// The worker's message handling, independent of how it is hosted: worker/worker.js runs it
// in a browser Web Worker, tests/js/node_worker.mjs in a node worker thread (so the client's
// protocol, cancel and respawn logic is tested in node with the real ops and bindings).
//
// Cancel: a running wasm call never sees a later postMessage (the worker's event loop is
// blocked inside it), so cancellation is driven by the main thread (lib/client.js):
//  - cooperative, when the page is crossOriginIsolated: the client writes the request id into
//    a SharedArrayBuffer flag (sent with 'init'); our progress callback reads it with Atomics
//    on every core progress update and answers "stop", and the core returns Cancelled. The
//    worker and its loaded meshes survive.
//  - otherwise (or if the op does not stop within a grace period, e.g. inside a long
//    factorization between two progress updates) the client terminates the worker and starts
//    a new one, replaying the requests marked to restore its state (the current mesh's load).
// A 'cancel' message is still honoured for requests queued behind the running one.
import { MeshMorphError } from '../lib/errors.js';
import { errorMessage, transferList } from '../lib/protocol.js';

// Progress messages are throttled: the core reports on every Lanczos step (hundreds per
// second); a progress bar needs ~20 updates per second and postMessage is not free.
const progressIntervalMs = 50;

// loadModule: (init message) => Promise<Emscripten module | {module, note}>; opFiles: {file: {ops}} (the ops list,
// worker/ops/index.js); post: (message, transferList) => void.
export function createWorkerRuntime({ loadModule, opFiles, post }) {
  let ctx = null;
  let ops = null;
  let cancelFlag = null;          // Int32Array over a SharedArrayBuffer, or null
  const cancelledIds = new Set(); // 'cancel' messages for requests not started yet

  const send = (message, buffers) => post(message, transferList(buffers));

  async function init(message) {
    try {
      ops = collectOps(opFiles);
      cancelFlag = message.cancelFlag instanceof Int32Array ? message.cancelFlag : null;
      const loaded = await loadModule(message);
      // loadModule gives the module, or {module, note} (worker.js: which build, and why).
      const module = loaded?.module ?? loaded;
      ctx = { module, state: { meshes: new Map() }, progress: () => true };
      const threads = typeof module.threads === 'function' ? module.threads() : { threaded: false, maxThreads: 1 };
      send({
        type: 'ready', ops: [...ops.keys()], cooperativeCancel: Boolean(cancelFlag),
        threads: { threaded: threads.threaded, maxThreads: threads.maxThreads }, note: loaded?.note || '',
      });
    } catch (e) {
      send(errorMessage(null, new MeshMorphError('InitFailed', `could not start the geometry module: ${e?.message || e}`, { fatal: true })));
    }
  }

  const isCancelled = (id) => cancelledIds.has(id) || (cancelFlag !== null && Atomics.load(cancelFlag, 0) === id);

  function run({ id, op, options, buffers }) {
    if (cancelledIds.delete(id)) {
      send(errorMessage(id, new MeshMorphError('Cancelled', 'cancelled before it started')));
      return;
    }
    const entry = ops?.get(op);
    if (!ctx || !entry) {
      send(errorMessage(id, new MeshMorphError('InvalidArgument', ctx ? `unknown op '${op}'` : 'worker is not initialised')));
      return;
    }
    let lastPost = -Infinity;
    let lastStage = '';
    ctx.progress = (stage, fraction) => {
      const now = performance.now();
      if (stage !== lastStage || now - lastPost >= progressIntervalMs) {
        lastPost = now;
        lastStage = stage;
        send({ type: 'progress', id, stage, fraction });
      }
      return !isCancelled(id);
    };
    try {
      const result = entry.fn(ctx, options || {}, buffers || {});
      send({ type: 'result', id, buffers: result.buffers || {}, info: result.info || {} }, result.buffers);
    } catch (e) {
      send(errorMessage(id, failure(op, e)));
    } finally {
      ctx.progress = () => true;
    }
  }

  return function onMessage(message) {
    switch (message?.type) {
      case 'init': return init(message);
      case 'run': return run(message);
      case 'cancel': cancelledIds.add(message.id); return undefined;
      default:
        send(errorMessage(message?.id ?? null, new MeshMorphError('InvalidArgument', `unknown message type '${message?.type}'`)));
        return undefined;
    }
  };
}

// What an op's exception means for the client: a MeshMorphError as it is (a data error the
// op reported); a trap inside wasm (abort, unreachable, out of memory) leaves the module
// unusable, so it is fatal and the client replaces this worker; anything else is a bug.
function failure(op, e) {
  if (e instanceof MeshMorphError) return e;
  const trapped = e instanceof WebAssembly.RuntimeError || /abort|out of memory/i.test(String(e?.message));
  return new MeshMorphError(trapped ? 'Crashed' : 'Internal', `${op}: ${e?.message || e}`, { fatal: trapped });
}

function collectOps(opFiles) {
  const ops = new Map();
  for (const [file, exports] of Object.entries(opFiles)) {
    for (const [name, fn] of Object.entries(exports.ops || {})) {
      if (ops.has(name)) throw new MeshMorphError('Internal', `op '${name}' is defined in ${ops.get(name).file} and ${file}`);
      ops.set(name, { fn, file });
    }
  }
  return ops;
}
