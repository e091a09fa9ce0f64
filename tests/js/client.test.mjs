// The main-thread client (web/src/lib/client.js) against the real worker runtime, ops and wasm
// bindings, hosted in node worker threads (node_worker.mjs): request ids, progress,
// transfer, both cancel strategies, restoring state into a replacement worker, and
// respawning a worker that fails to start or traps.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { Worker } from 'node:worker_threads';
import { MeshMorphClient } from '../../web/src/lib/client.js';
import { dataBytes } from './wasm_module.mjs';

const workerUrl = new URL('./node_worker.mjs', import.meta.url);

// The browser Worker interface over a node worker thread.
class NodeWorker {
  constructor(workerData) {
    this.thread = new Worker(workerUrl, { workerData });
    this.thread.on('message', (data) => this.onmessage?.({ data }));
    this.thread.on('error', (e) => {
      const event = { message: e.message, defaultPrevented: false, preventDefault() { this.defaultPrevented = true; } };
      this.onerror?.(event);
      NodeWorker.errors.push(event);
    });
  }
  postMessage(message, transfer) { this.thread.postMessage(message, transfer); }
  terminate() { this.thread.terminate(); }
}
NodeWorker.errors = []; // every error event given to a client, to check it was handled

function makeClient(options = {}, workerData = {}) {
  let started = 0;
  const client = new MeshMorphClient({
    createWorker: () => { started += 1; return new NodeWorker(workerData); },
    cancelGraceMs: 3000,
    ...options,
  });
  return { client, started: () => started };
}

async function loadArmadillo(client) {
  const bytes = dataBytes('edit/armadillo.ply');
  const { promise } = client.run('load', { name: 'armadillo.ply' }, { 'armadillo.ply': bytes }, { restoreKey: 'mesh:main' });
  const result = await promise;
  assert.equal(bytes.byteLength, 0, 'the file bytes were transferred, not copied');
  return result;
}

// Runs eigs k=100 (seconds on the armadillo) and cancels it at its first progress message.
async function cancelLongEigs(client) {
  let cancelled = false;
  const { id, promise } = client.run('eigs', { k: 100 }, {}, {
    onProgress: () => {
      if (!cancelled) { cancelled = true; client.cancel(id); }
    },
  });
  const started = Date.now();
  await assert.rejects(promise, (e) => e.code === 'Cancelled');
  assert.ok(cancelled, 'progress was reported before the result');
  return Date.now() - started;
}

test('load and eigs through the client: progress, results, transfer', async () => {
  const { client } = makeClient();
  try {
    const ready = await client.ready;
    assert.ok(ready.ops.includes('load') && ready.ops.includes('eigs'));
    const { info, buffers } = await loadArmadillo(client);
    assert.equal(info.weldedVertices, 14587);
    assert.ok(buffers.positions instanceof Float32Array);
    const stages = [];
    const { promise } = client.run('eigs', { k: 8 }, {}, { onProgress: (stage, f) => stages.push([stage, f]) });
    const eigs = await promise;
    assert.equal(eigs.buffers.eigenvalues.length, 8);
    assert.ok(stages.length > 0 && stages.every(([s, f]) => s === 'eigenbasis' && f >= 0 && f <= 1));
    await assert.rejects(client.run('nonsense').promise, (e) => e.code === 'InvalidArgument' && /unknown op/.test(e.message));
    await assert.rejects(client.run('load', { name: 'x.ply' }, { 'x.ply': new Uint8Array([1, 2, 3]) }).promise, (e) => e.code === 'ParseError');
  } finally {
    client.dropWorker();
  }
});

test('cooperative cancel (SharedArrayBuffer flag): the worker and its mesh survive', async () => {
  const { client, started } = makeClient({ cancelMode: 'cooperative' });
  try {
    assert.equal(client.cancelMode, 'cooperative');
    await loadArmadillo(client);
    const ms = await cancelLongEigs(client);
    assert.ok(ms < 3000, `cancel took ${ms} ms`);
    assert.equal(client.restarts, 0);
    assert.equal(started(), 1);
    const { buffers } = await client.run('eigs', { k: 4 }).promise;
    assert.equal(buffers.eigenvalues.length, 4);
  } finally {
    client.dropWorker();
  }
});

test('terminate cancel: a new worker replays the load; queued requests are aborted', async () => {
  const { client, started } = makeClient({ cancelMode: 'terminate' });
  try {
    assert.equal(client.cancelMode, 'terminate');
    await loadArmadillo(client);
    const long = cancelLongEigs(client);
    const queued = client.run('eigs', { k: 3 }).promise; // waits behind the long one
    const [ms] = await Promise.all([long, assert.rejects(queued, (e) => e.code === 'Aborted')]);
    assert.ok(ms < 3000, `cancel took ${ms} ms`);
    assert.equal(client.restarts, 1);
    assert.equal(started(), 2);
    // No new load: the replacement worker got the armadillo from the restore list.
    const { info } = await client.run('eigs', { k: 4 }).promise;
    assert.equal(info.weldedVertices, 14587);
  } finally {
    client.dropWorker();
  }
});

test('a cancel that times out: requests made after it wait and run in the new worker, not Aborted; a waiting request cancels at once', async () => {
  const restarts = [];
  const { client, started } = makeClient({ cancelMode: 'cooperative', cancelGraceMs: 300, onRestart: (detail) => restarts.push(detail) });
  try {
    await loadArmadillo(client);
    const blocking = client.run('block', { ms: 1500 }); // no progress: the flag is never read
    await new Promise((resolve) => setTimeout(resolve, 100)); // it has started in the worker
    assert.equal(client.cancel(blocking.id), true);
    const after = client.run('eigs', { k: 3 }); // a new run replacing the cancelled one
    const dropped = client.run('eigs', { k: 3 });
    assert.equal(client.cancel(dropped.id), true, 'a request still waiting can be cancelled');
    await assert.rejects(dropped.promise, (e) => e.code === 'Cancelled' && /before it started/.test(e.message));
    await assert.rejects(blocking.promise, (e) => e.code === 'Cancelled' && /did not stop in time/.test(e.message));
    const { info } = await after.promise;
    assert.equal(info.weldedVertices, 14587, 'the new worker has the armadillo again');
    assert.equal(client.restarts, 1);
    assert.equal(started(), 2);
    assert.deepEqual(restarts.map((r) => [r.code, r.why, r.restored]), [['Cancelled', 'did not stop in time', ['mesh:main']]]);
    // A cancel that the op honours in time: no restart, and the request after it runs.
    const quick = client.run('block', { ms: 100 });
    client.cancel(quick.id);
    const next = client.run('eigs', { k: 3 });
    await quick.promise.catch((e) => assert.equal(e.code, 'Cancelled'));
    assert.equal((await next.promise).buffers.eigenvalues.length, 3);
    assert.equal(client.restarts, 1);
  } finally {
    client.dropWorker();
  }
});

test('a worker that fails to start is replaced; after too many failures requests reject with InitFailed', async () => {
  const failInits = new Int32Array(new SharedArrayBuffer(4));
  Atomics.store(failInits, 0, 2);
  const flaky = makeClient({ maxInitAttempts: 3 }, { failInits });
  try {
    await flaky.client.ready;
    assert.equal(flaky.started(), 3, 'two failed starts, then a good one');
    const { info } = await flaky.client.run('load', { name: 'hand.ply' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') }).promise;
    assert.equal(info.weldedVertices, 810);
  } finally {
    flaky.client.dropWorker();
  }

  const broken = new Int32Array(new SharedArrayBuffer(4));
  Atomics.store(broken, 0, 1000);
  const dead = makeClient({ maxInitAttempts: 2 }, { failInits: broken });
  await assert.rejects(dead.client.ready, (e) => e.code === 'InitFailed' && /simulated start failure/.test(e.message));
  await assert.rejects(dead.client.run('eigs', { k: 3 }).promise, (e) => e.code === 'InitFailed');
  dead.client.dropWorker();
});

test('a worker that never answers its start is replaced after the start timeout, and the page hears why', async () => {
  const hangInits = new Int32Array(new SharedArrayBuffer(4));
  Atomics.store(hangInits, 0, 1);
  const notes = [];
  const slow = makeClient({ maxInitAttempts: 3, startTimeoutMs: 3000, onStatus: (text) => notes.push(text) }, { hangInits });
  try {
    const started = Date.now();
    await slow.client.ready;
    assert.equal(slow.started(), 2, 'one hung start, then a good one');
    assert.ok(Date.now() - started >= 2900, 'the hung worker was given its time');
    assert.ok(notes.some((n) => /attempt 1.*no answer from the worker in 3 s/.test(n)), `notes: ${notes.join(' | ')}`);
    const { info } = await slow.client.run('load', { name: 'hand.ply' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') }).promise;
    assert.equal(info.weldedVertices, 810);
  } finally {
    slow.client.dropWorker();
  }
});

test('a wasm trap replaces the worker and restores the mesh', async () => {
  const { client, started } = makeClient();
  try {
    await client.run('load', { name: 'hand.ply' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') }, { restoreKey: 'mesh:main' }).promise;
    await assert.rejects(client.run('crash').promise, (e) => e.code === 'Crashed' && /unreachable/.test(e.message));
    const { info } = await client.run('eigs', { k: 3 }).promise;
    assert.equal(info.weldedVertices, 810);
    assert.equal(started(), 2);
    assert.equal(client.restarts, 1);
  } finally {
    client.dropWorker();
  }
});

test('running out of wasm memory replaces the worker and restores the mesh (onRestart tells)', async () => {
  const restarts = [];
  const { client, started } = makeClient({ onRestart: (detail) => restarts.push(detail) });
  try {
    await client.ready;
    await loadArmadillo(client);
    const { info } = await client.run('debugExhaustMemory').promise;
    assert.ok(info.allocatedMB > 2000, `the heap grew to ${info.allocatedMB} MB only`);
    await assert.rejects(client.run('eigs', { k: 10 }).promise, (e) => e.code === 'OutOfMemory' && /out of memory/.test(e.message));
    await client.ready;
    assert.equal(client.restarts, 1);
    assert.equal(started(), 2);
    assert.deepEqual(restarts.map((r) => [r.code, r.restored]), [['OutOfMemory', ['mesh:main']]]);
    const { info: report } = await client.run('validate', {}).promise;
    assert.equal(report.report.vertices, 14587, 'the new worker has the armadillo again');
  } finally {
    client.dropWorker();
  }
});

test('a worker that dies (uncaught error) is replaced and the mesh restored', async () => {
  const restarts = [];
  const { client } = makeClient({ onRestart: (detail) => restarts.push(detail) });
  try {
    await client.ready;
    await loadArmadillo(client);
    // The op answers and then the worker dies; under load the death can overtake the answer, so
    // the request may also be rejected as Crashed.
    await client.run('debugCrash').promise.catch((e) => { if (e.code !== 'Crashed') throw e; });
    for (let i = 0; i < 100 && !restarts.length; ++i) await new Promise((resolve) => setTimeout(resolve, 50));
    assert.equal(restarts.length, 1, 'no restart after the worker died');
    assert.equal(restarts[0].code, 'Crashed');
    // The client handled the error event: no uncaught error reaches the page (Firefox showed one).
    const crash = NodeWorker.errors.find((e) => /debugCrash/.test(e.message));
    assert.ok(crash && crash.defaultPrevented, 'the worker\'s error event was not marked handled (preventDefault)');
    const { info } = await client.run('validate', {}).promise;
    assert.equal(info.report.vertices, 14587);
  } finally {
    client.dropWorker();
  }
});
