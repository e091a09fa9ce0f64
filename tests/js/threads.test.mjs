// The threaded wasm modules (the -pthread link of the same objects, meshmorph_node_mt; the page's module when crossOriginIsolated)
// against the single-threaded one, through the worker's ops: the stages that run on two threads
// (the transfer's cage and mean-value coordinates beside the eigenbases, the mean-value rows in two
// halves; the editor's Poisson factor beside the Eq. 7 system, whose columns and supernodal
// factor are split in two; the retargeter's per-frame vertex product in column blocks) give the same bits as one thread and as the single-threaded build;
// the automatic part sets run side by side; progress still comes from the calling thread only,
// and cancel stops a threaded run.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { ops as editOps } from '../../web/src/worker/ops/edit.js';
import { ops as meshOps } from '../../web/src/worker/ops/mesh.js';
import { ops as retargetOps } from '../../web/src/worker/ops/retarget.js';
import { ops as transferOps } from '../../web/src/worker/ops/transfer.js';
import { dataBytes, fileBuffers, loadModule, makeContext } from './wasm_module.mjs';

const same = (a, b) => a.length === b.length && Buffer.from(a.buffer, a.byteOffset, a.byteLength).equals(Buffer.from(b.buffer, b.byteOffset, b.byteLength));

async function withThreads(variant, n, fn) {
  const module = await loadModule(variant);
  module.setMaxThreads(n);
  try {
    return await fn(await makeContext(() => true, variant));
  } finally {
    module.setMaxThreads(0);
  }
}

test('the two builds say whether they have threads; setMaxThreads caps and restores', async () => {
  const single = await loadModule('single');
  const threaded = await loadModule('threaded');
  assert.deepEqual(single.threads(), { ok: true, threaded: false, maxThreads: 1 });
  assert.equal(single.setMaxThreads(4).maxThreads, 1, 'the single-threaded build stays on one thread');
  const initial = threaded.threads();
  assert.equal(initial.threaded, true);
  assert.ok(initial.maxThreads >= 1);
  assert.equal(threaded.setMaxThreads(1).maxThreads, 1);
  assert.equal(threaded.setMaxThreads(3).maxThreads, 3);
  assert.equal(threaded.setMaxThreads(0).maxThreads, initial.maxThreads);
});

function transferCat(ctx, progress) {
  meshOps.load(ctx, { name: 'cat-07.ply', slot: 'reference' }, fileBuffers('pose/cat-07.ply'));
  meshOps.load(ctx, { name: 'cat-reference.ply', slot: 'source' }, fileBuffers('pose/cat-reference.ply'));
  if (progress) ctx.progress = progress;
  return transferOps.transfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', method: 'yin' }).buffers.positions;
}

test('transfer (Yin, 7.2k vertices): one thread, two threads and the single-threaded build agree to the bit', async () => {
  const single = await withThreads('single', 1, (ctx) => transferCat(ctx));
  const one = await withThreads('threaded', 1, (ctx) => transferCat(ctx));
  const fractions = [];
  const two = await withThreads('threaded', 2, (ctx) => transferCat(ctx, (stage, f) => { fractions.push(f); return true; }));
  assert.ok(same(single, one), 'threaded build on one thread differs from the single-threaded build');
  assert.ok(same(single, two), 'threaded build on two threads differs from the single-threaded build');
  // The cage thread's progress reaches the sink through the calling thread, in order.
  assert.ok(fractions.length > 10, `${fractions.length} progress updates`);
  for (let i = 1; i < fractions.length; i++) assert.ok(fractions[i] >= fractions[i - 1] - 1e-12, `progress went back at ${i}: ${fractions[i - 1]} → ${fractions[i]}`);
});

test('cancel stops a two-thread transfer (the cage thread included); the module keeps working', async () => {
  await withThreads('threaded', 2, async (ctx) => {
    let calls = 0;
    assert.throws(() => transferCat(ctx, () => ++calls < 40), (e) => e instanceof MeshMorphError && e.code === 'Cancelled');
    ctx.progress = () => true;
    const after = transferOps.transfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', method: 'yin' }).buffers.positions;
    const single = await withThreads('single', 1, (c) => transferCat(c));
    assert.ok(same(after, single), 'the run after a cancel differs');
  });
});

// Automatic parts (one round of three candidate sets, at most three parts each): the sets run side
// by side on the pool (core/transfer/part_transfer.cpp); one thread and two give the same bits, and
// a cancel during the parts stops the sets on the pool threads too.
function partsCat(ctx, progress) {
  meshOps.load(ctx, { name: 'cat-05.ply', slot: 'reference' }, fileBuffers('pose/cat-05.ply'));
  meshOps.load(ctx, { name: 'cat-reference.ply', slot: 'source' }, fileBuffers('pose/cat-reference.ply'));
  if (progress) ctx.progress = progress;
  return transferOps.partTransfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', parts: 'auto',
    partOptions: { max_parts: 3, proposal_rounds: 1 } });
}

test('automatic parts: the candidate sets side by side give the same bits on one thread and two; cancel stops them', async () => {
  const one = await withThreads('threaded', 1, (ctx) => partsCat(ctx));
  const two = await withThreads('threaded', 2, (ctx) => partsCat(ctx));
  assert.ok(one.info.proposals.tried >= 2, `${one.info.proposals.tried} candidate sets`);
  assert.ok(same(one.buffers.positions, two.buffers.positions), 'automatic parts: one thread and two differ');
  assert.deepEqual(two.info.parts.map((p) => [p.name, p.ok]), one.info.parts.map((p) => [p.name, p.ok]));
  await withThreads('threaded', 2, async (ctx) => {
    let cancelAt = 0;
    assert.throws(() => partsCat(ctx, (stage, f) => {
      if (f < 0.5) return true;
      cancelAt ||= Date.now();
      return false;
    }), (e) => e instanceof MeshMorphError && e.code === 'Cancelled');
    assert.ok(cancelAt > 0, 'the parts never reported past half way');
    assert.ok(Date.now() - cancelAt < 5000, `the cancel took ${Date.now() - cancelAt} ms to stop the sets`);
    // Every set has stopped before the op returns (its tasks are waited for): the module is free.
    // (A run after a cancel equals a fresh one: the transfer cancel test above.)
    ctx.progress = () => true;
    assert.equal(meshOps.load(ctx, { name: 'cat-05.ply', slot: 'reference' }, fileBuffers('pose/cat-05.ply')).info.weldedVertices, 7207);
  });
});

// Armadillo (14.6k vertices) with the lowest 10 % fixed and the top 10 % dragged: an Eq. 7 system
// large enough for the two-half column assembly and the split supernodal factor.
function editArmadillo(ctx) {
  meshOps.load(ctx, { name: 'armadillo.ply' }, fileBuffers('edit/armadillo.ply'));
  editOps.editCreate(ctx, { spec: {
    fixed: { slabs: [{ axis: 'long', from: 0, to: 0.1 }] },
    handles: [{ select: { slabs: [{ axis: 'long', from: 0.9, to: 1 }] } }],
  } });
  const drag = editOps.editDrag(ctx, { transforms: [{ translate: [0.05, 0.1, 0], rotate: { axis: [0, 0, 1], degrees: 30 } }] }).buffers.positions;
  const fin = editOps.editFinalize(ctx, { mode: 'keep' }).buffers.positions;
  editOps.editDispose(ctx, {});
  return { drag, fin };
}

test('edit (14.6k vertices): precompute, drag and finalize agree to the bit across builds and thread counts', async () => {
  const single = await withThreads('single', 1, (ctx) => editArmadillo(ctx));
  const one = await withThreads('threaded', 1, (ctx) => editArmadillo(ctx));
  const two = await withThreads('threaded', 2, (ctx) => editArmadillo(ctx));
  for (const [name, r] of [['one thread', one], ['two threads', two]]) {
    assert.ok(same(single.drag, r.drag), `drag: threaded build on ${name} differs`);
    assert.ok(same(single.fin, r.fin), `finalize: threaded build on ${name} differs`);
  }
  let moved = 0;
  const rest = (await makeContext(() => true, 'single'));
  meshOps.load(rest, { name: 'armadillo.ply' }, fileBuffers('edit/armadillo.ply'));
  const W = rest.state.meshes.get('main').weldedPositions;
  for (let i = 0; i < W.length; i++) moved = Math.max(moved, Math.abs(W[i] - two.drag[i]));
  assert.ok(moved > 0.01, `the drag did not move the mesh (${moved})`);
});

// Fox (Walk) → wolf0 with its placed joints: precompute and 4 frames.
function retargetFox(ctx) {
  const { info } = retargetOps.retargetPrepare(
    ctx,
    { sourceName: 'Fox.glb', targetName: 'wolf0.ply', targetJointsJson: new TextDecoder().decode(dataBytes('joints/wolf0_joints.json')),
      clip: 'Walk', fps: 15, first_frame: 0, last_frame: 4 },
    { source: dataBytes('anim/Fox/glTF-Binary/Fox.glb'), target: dataBytes('anim/wolf0.ply') });
  const frames = retargetOps.retargetFrames(ctx, { session: info.session, first: 0 }).buffers.positions;
  retargetOps.retargetDispose(ctx, { session: info.session });
  return frames;
}

test('retarget (Fox → wolf0): frames agree to the bit across builds and thread counts', async () => {
  const single = await withThreads('single', 1, (ctx) => retargetFox(ctx));
  const two = await withThreads('threaded', 2, (ctx) => retargetFox(ctx));
  const four = await withThreads('threaded', 4, (ctx) => retargetFox(ctx));
  assert.ok(single.length > 3 * 1000 && single.every(Number.isFinite));
  assert.ok(same(single, two), 'two threads differ from the single-threaded build');
  assert.ok(same(single, four), 'four threads differ from the single-threaded build');
});

