// Main-thread side of the worker protocol (protocol.js): request ids, pending[id] =
// {resolve, reject}, progress callbacks, cancel, and replacing a worker that failed.
//
// Cancel strategy (tested by tests/e2e/run.mjs and tests/js/client.test.mjs, both ways):
//  1. cooperative — when crossOriginIsolated (vite serves COOP/COEP), a SharedArrayBuffer
//     flag is shared with the worker; cancel(id) stores id there, the core's progress sink
//     sees it and the op ends with code Cancelled. Cheap: the worker keeps its loaded meshes.
//  2. terminate — without SharedArrayBuffer, or when the op has not stopped after
//     `cancelGraceMs` (a factorization between two progress updates can take a while), the
//     worker is terminated and a new one started. Its state is rebuilt by replaying the
//     requests that were marked `restoreKey` (e.g. the current mesh's load), from copies kept
//     here, before any new request runs.
// The same replacement happens when the worker fails to initialise (up to `maxInitAttempts`),
// reports a fatal error (a wasm trap), dies (an uncaught error: its 'error' event), or runs out
// of wasm memory (code OutOfMemory: the 4 GB heap never shrinks, so that worker would fail
// again and again): the request fails with that code, the other pending ones with Aborted, and
// `onRestart({why, code})` is called when the new worker has replayed the restore requests
// (`restored`: their keys) — the page says so and panels drop state the old worker held. A
// cancel that ends in a restart (2. above) calls it too, with code Cancelled: sessions (edit,
// retarget) lived in the old worker.
// Requests made while a cancel is pending wait until the cancelled request has ended (or its
// worker was replaced) before they are posted: a new run that replaces a cancelled one (a
// changed option, a new joints file) would otherwise sit in the old worker's queue and die
// with it (Aborted) when the cancelled op does not stop in time — e.g. an SVD of the harmonic
// map, one indivisible Eigen call, takes ~0.6 s on an idle machine and more under load.
import { MeshMorphError, toMeshMorphError } from './errors.js';
import { cloneBuffers, transferList } from './protocol.js';

export class MeshMorphClient {
  // createWorker: () => Worker-like {postMessage, terminate, onmessage, onerror}.
  // cancelMode: 'auto' (cooperative when crossOriginIsolated), 'cooperative' or 'terminate'.
  // onStatus: (text) => void, for diagnostics (worker restarts).
  // startTimeoutMs: a worker that neither says 'ready' nor fails within this time is replaced
  // (doubling the wait each attempt: a slow machine compiling the module is not a hang).
  constructor({ createWorker, threadedModuleUrl = null, maxInitAttempts = 3, startTimeoutMs = 30000, cancelGraceMs = 5000, cancelMode = 'auto', onStatus = () => {}, onRestart = () => {} }) {
    this.createWorker = createWorker;
    // The threaded wasm build needs shared memory: offered to the worker only when this page is
    // crossOriginIsolated (worker/worker.js falls back to the single-threaded build otherwise).
    this.threadedModuleUrl = globalThis.crossOriginIsolated === true ? threadedModuleUrl : null;
    this.threads = { threaded: false, maxThreads: 1 }; // from the worker's 'ready'
    this.onRestart = onRestart;
    this.maxInitAttempts = maxInitAttempts;
    this.startTimeoutMs = startTimeoutMs;
    this.cancelGraceMs = cancelGraceMs;
    this.onStatus = onStatus;
    const sharedMemory = typeof SharedArrayBuffer === 'function';
    this.cooperative = sharedMemory && (cancelMode === 'cooperative' || (cancelMode === 'auto' && globalThis.crossOriginIsolated === true));
    this.nextId = 1;
    this.pending = new Map();   // id → {resolve, reject, onProgress, op, cancelTimer}
    this.restore = new Map();   // restoreKey → {op, options, buffers (our copies)}
    this.worker = null;
    this.cancelFlag = null;
    this.restarts = 0;          // how many times a worker was replaced (shown for tests)
    this.cancelling = new Set(); // ids cancelled and not yet ended
    this.cancelsEnded = null;    // {promise, resolve} while `cancelling` is not empty
    this.unsent = new Map();     // id → reject, for run() requests still waiting to be posted
    this.ready = this.spawn();
  }

  get cancelMode() { return this.cooperative ? 'cooperative' : 'terminate'; }

  // For the status line: how the worker computes and cancels, e.g. "2 threads · cancel: cooperative".
  get runtimeSummary() {
    const { threaded, maxThreads } = this.threads;
    const threads = threaded && maxThreads > 1 ? `${maxThreads} threads` : 'one thread';
    return `${threads} · cancel: ${this.cancelMode}`;
  }

  // Starts a worker and waits for 'ready', retrying with a fresh worker on failure; then
  // replays the restore requests. Resolves to the ready message.
  async spawn() {
    let lastError = null;
    for (let attempt = 1; attempt <= this.maxInitAttempts; ++attempt) {
      try {
        const ready = await this.startOne(this.startTimeoutMs * 2 ** (attempt - 1));
        await this.replayRestore();
        return ready;
      } catch (e) {
        lastError = e;
        this.dropWorker();
        this.onStatus(`worker start failed (attempt ${attempt}): ${e.message}`);
      }
    }
    throw new MeshMorphError('InitFailed', `the geometry worker could not start: ${lastError?.message || lastError}`);
  }

  startOne(timeoutMs) {
    let timer = null;
    return new Promise((resolve, reject) => {
      const worker = this.createWorker();
      this.worker = worker;
      this.cancelFlag = this.cooperative ? new Int32Array(new SharedArrayBuffer(4)) : null;
      timer = setTimeout(() => reject(new MeshMorphError('InitFailed', `no answer from the worker in ${Math.round(timeoutMs / 1000)} s`)), timeoutMs);
      worker.onmessage = (event) => {
        const message = event.data;
        if (message.type === 'ready') {
          if (message.threads) this.threads = message.threads;
          if (message.note) this.onStatus(message.note);
          worker.onmessage = (e) => this.handle(worker, e.data);
          worker.onerror = (e) => {
            // Handled here (a new worker, the page told): not also an uncaught error of the page
            // (Firefox reports a worker's unhandled error on the page otherwise).
            e.preventDefault?.();
            this.crashed(worker, e.message || 'worker error');
          };
          resolve(message);
        } else if (message.type === 'error') {
          reject(toMeshMorphError(message));
        }
      };
      worker.onerror = (e) => {
        e.preventDefault?.();
        reject(new MeshMorphError('InitFailed', e.message || 'worker script failed to load'));
      };
      worker.postMessage({ type: 'init', cancelFlag: this.cancelFlag, threadedModuleUrl: this.threadedModuleUrl });
    }).finally(() => clearTimeout(timer));
  }

  async replayRestore() {
    for (const [key, request] of this.restore) {
      try {
        await this.send(request.op, request.options, cloneBuffers(request.buffers), {});
      } catch (e) {
        // The state could not be rebuilt (should not happen: it loaded before); forget it so
        // later requests report "no mesh loaded" rather than failing forever.
        this.restore.delete(key);
        this.onStatus(`could not restore '${key}': ${e.message}`);
      }
    }
  }

  // Runs `op` in the worker. Returns {id, promise}; promise resolves to {buffers, info}.
  // restoreKey: remember this request (with copies of its buffers) so that a replacement
  // worker replays it; a later request with the same key replaces it.
  run(op, options = {}, buffers = {}, { onProgress, restoreKey } = {}) {
    const id = this.nextId++;
    let kept = null;
    if (restoreKey) kept = { op, options, buffers: cloneBuffers(buffers) };
    const promise = new Promise((resolve, reject) => {
      this.unsent.set(id, reject);
      this.whenReady().then(() => this.afterCancels()).then(() => {
        if (!this.unsent.delete(id)) return; // cancelled while it waited: already rejected
        this.sendWithId(id, op, options, buffers, { onProgress }).then(resolve, reject);
      }, (e) => {
        this.unsent.delete(id);
        reject(e);
      });
    }).then((result) => {
      if (restoreKey) this.restore.set(restoreKey, kept);
      return result;
    });
    return { id, promise };
  }

  // Waits for the current worker, following replacements that happen meanwhile. After a
  // failed start (InitFailed) the next request tries once more with a new worker.
  async whenReady() {
    for (;;) {
      const ready = this.ready;
      try {
        await ready;
      } catch (e) {
        if (ready !== this.ready) continue;
        if (this.failedReady === ready) throw e;
        this.failedReady = this.ready = this.spawn();
        continue;
      }
      if (ready !== this.ready) continue;
      if (this.worker) return;
      this.ready = this.spawn(); // resolved but no worker: cannot normally happen; recover
    }
  }

  // Resolves once no cancelled request is still running, on a ready worker (a cancel that
  // timed out replaced it meanwhile).
  async afterCancels() {
    while (this.cancelsEnded) {
      await this.cancelsEnded.promise;
      await this.whenReady();
    }
  }

  send(op, options, buffers, handlers) {
    return this.sendWithId(this.nextId++, op, options, buffers, handlers);
  }

  sendWithId(id, op, options, buffers, { onProgress } = {}) {
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, onProgress, op });
      this.worker.postMessage({ type: 'run', id, op, options, buffers }, transferList(buffers));
    });
  }

  handle(worker, message) {
    if (worker !== this.worker) return; // a message from a worker we already dropped
    const entry = this.pending.get(message.id);
    switch (message.type) {
      case 'progress':
        entry?.onProgress?.(message.stage, message.fraction);
        break;
      case 'result':
        if (!entry) return;
        this.settle(message.id);
        entry.resolve({ buffers: message.buffers, info: message.info });
        break;
      case 'error':
        if (message.fatal || message.code === 'OutOfMemory') {
          this.crashed(worker, message.message, message.id, message.code);
          return;
        }
        if (!entry) return;
        this.settle(message.id);
        entry.reject(toMeshMorphError(message));
        break;
      default:
        break;
    }
  }

  settle(id) {
    const entry = this.pending.get(id);
    if (entry?.cancelTimer) clearTimeout(entry.cancelTimer);
    if (this.cancelFlag && Atomics.load(this.cancelFlag, 0) === id) Atomics.store(this.cancelFlag, 0, 0);
    this.pending.delete(id);
    if (this.cancelling.delete(id) && this.cancelling.size === 0 && this.cancelsEnded) {
      const { resolve } = this.cancelsEnded;
      this.cancelsEnded = null;
      resolve();
    }
  }

  // Asks the request `id` to stop; it then rejects with code Cancelled (at once when it was
  // still waiting to be posted). Returns false when the request is no longer running.
  cancel(id) {
    const reject = this.unsent.get(id);
    if (reject) {
      this.unsent.delete(id);
      reject(new MeshMorphError('Cancelled', 'cancelled before it started'));
      return true;
    }
    const entry = this.pending.get(id);
    if (!entry) return false;
    this.cancelling.add(id);
    if (!this.cancelsEnded) {
      let resolve;
      const promise = new Promise((r) => { resolve = r; });
      this.cancelsEnded = { promise, resolve };
    }
    if (this.cooperative) {
      Atomics.store(this.cancelFlag, 0, id);
      this.worker.postMessage({ type: 'cancel', id }); // for the case it is still queued
      entry.cancelTimer = setTimeout(() => {
        if (this.pending.has(id)) this.restart(id, 'did not stop in time');
      }, this.cancelGraceMs);
    } else {
      this.restart(id, 'terminated');
    }
    return true;
  }

  // Terminates the worker; `cancelledId` rejects with Cancelled, other pending requests with
  // Aborted (their buffers went to the dead worker); then a new worker is started, and
  // onRestart tells the page (code Cancelled) once it has the restored state.
  restart(cancelledId, why) {
    const pending = [...this.pending.entries()];
    this.dropWorker();
    for (const [id, entry] of pending) {
      this.settle(id);
      if (id === cancelledId) entry.reject(new MeshMorphError('Cancelled', `cancelled (worker ${why} and restarted)`));
      else entry.reject(new MeshMorphError('Aborted', 'the worker was restarted while this request waited'));
    }
    this.restarts += 1;
    this.ready = this.spawn();
    this.ready.then(() => this.onRestart({ why, code: 'Cancelled', restored: [...this.restore.keys()] }), () => {});
    return this.ready;
  }

  crashed(worker, text, failedId = null, code = 'Crashed') {
    if (worker !== this.worker) return;
    const pending = [...this.pending.entries()];
    this.dropWorker();
    for (const [id, entry] of pending) {
      this.settle(id);
      entry.reject(new MeshMorphError(id === failedId || failedId === null ? code : 'Aborted', text));
    }
    this.restarts += 1;
    this.onStatus(`the geometry worker failed (${code}); starting a new one`);
    this.ready = this.spawn();
    this.ready.then(() => this.onRestart({ why: text, code, restored: [...this.restore.keys()] }), () => {});
  }

  // Stops replaying a restore request (e.g. the mesh it loaded was unloaded).
  forget(restoreKey) {
    this.restore.delete(restoreKey);
  }

  dropWorker() {
    if (this.worker) {
      this.worker.onmessage = null;
      this.worker.onerror = null;
      this.worker.terminate();
    }
    this.worker = null;
  }
}
