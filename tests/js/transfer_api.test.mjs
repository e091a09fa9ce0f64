// API tests of wasm/bind_transfer.cpp through web/src/worker/ops/transfer.js (the functions the
// worker runs) with the node build of the module, and of the page's landmark file reader
// (web/src/lib/landmarks.js) on the repository's landmark files.
// Run: node --test tests/js/ (MM_WASM_DIR overrides the build directory).
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { LandmarkPairs, landmarkFile, readLandmarkFile } from '../../web/src/lib/landmarks.js';
import { ops as meshOps } from '../../web/src/worker/ops/mesh.js';
import { ops } from '../../web/src/worker/ops/transfer.js';
import { fileBuffers, makeContext, repoDir } from './wasm_module.mjs';

async function catPair() {
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'cat-07.ply', slot: 'reference' }, fileBuffers('pose/cat-07.ply'));
  meshOps.load(ctx, { name: 'cat-reference.ply', slot: 'source' }, fileBuffers('pose/cat-reference.ply'));
  return ctx;
}

function expectCode(fn, code, pattern) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof MeshMorphError, `expected a MeshMorphError, got ${e}`);
    assert.equal(e.code, code, `code of "${e.message}"`);
    if (pattern) assert.match(e.message, pattern);
    return true;
  });
}

test('transfer passes every schema option and compare takes the result positions', async () => {
  const ctx = await catPair();
  const base = { referenceSlot: 'reference', sourceSlot: 'source' };
  // num_coupled and mu are schema options the op used to drop; an unknown one is an error.
  const { buffers, info } = ops.transfer(ctx, { ...base, method: 'kovnatsky', num_coupled: 8, mu: 1 });
  assert.equal(buffers.positions.length, ctx.state.meshes.get('source').weldedPositions.length);
  assert.equal(info.k, 8);
  assert.equal(info.gamma.length, 64);
  expectCode(() => ops.transfer(ctx, { ...base, method: 'levy', no_such_option: 1 }), 'InvalidArgument');

  const metrics = ops.compare(ctx, { slotB: 'source' }, { positionsA: buffers.positions }).info;
  assert.ok(metrics.vertexErrorMean > 0.01, `the result did not move: ${JSON.stringify(metrics)}`);
  assert.ok(Number.isInteger(metrics.flippedFaces));
  const toReference = ops.compare(ctx, { slotB: 'reference' }, { positionsA: buffers.positions }).info;
  const sourceToReference = ops.compare(ctx, { slotA: 'source', slotB: 'reference' }).info;
  assert.ok(toReference.vertexErrorMean < sourceToReference.vertexErrorMean,
    `result ${toReference.vertexErrorMean}, source ${sourceToReference.vertexErrorMean} from the reference`);
  expectCode(() => ops.compare(ctx, { slotB: 'source' }, { positionsA: new Float32Array(9) }), 'InvalidArgument', /vertex order/);
});

test('different connectivity needs landmarks; the repository landmark file reads and runs', async () => {
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'cat-07.ply', slot: 'reference' }, fileBuffers('pose/cat-07.ply'));
  meshOps.load(ctx, { name: 'lion-reference.ply', slot: 'source' }, fileBuffers('pose/lion-reference.ply'));
  const base = { referenceSlot: 'reference', sourceSlot: 'source', method: 'levy' };
  expectCode(() => ops.transfer(ctx, base), 'InvalidArgument', /landmark/);
  const json = JSON.parse(fs.readFileSync(path.join(repoDir, 'data/landmarks/cat-lion.json'), 'utf8'));
  const counts = { referenceVertices: 7207, sourceVertices: 5000 };
  const pairs = readLandmarkFile(json, counts);
  assert.equal(pairs.length, 30);
  expectCode(() => ops.transfer(ctx, { ...base, landmarks: pairs.slice(0, 3) }), 'InvalidArgument');
  const { buffers } = ops.transfer(ctx, { ...base, landmarks: pairs });
  assert.equal(buffers.positions.length, 5000 * 3);
  assert.ok(buffers.positions.every(Number.isFinite));
  // Written back, the file has the same pairs.
  assert.deepEqual(readLandmarkFile(landmarkFile(pairs, { reference: 'a', source: 'b' }), counts), pairs);
  assert.throws(() => readLandmarkFile({ pairs: [[0, 5000]] }, counts), /out of range/);
  assert.throws(() => readLandmarkFile({ pairs: [[0]] }, counts), /not \[reference_vertex/);
  assert.throws(() => readLandmarkFile({}, counts), /"pairs"/);
});

test('partTransfer: a part file through the op; labels, the level-1 result and the parts used come back', async () => {
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'lion-05.ply', slot: 'reference' }, fileBuffers('pose/lion-05.ply'));
  meshOps.load(ctx, { name: 'lion-reference.ply', slot: 'source' }, fileBuffers('pose/lion-reference.ply'));
  // One front leg (the lion-05 proposal's tip, tests/part_transfer_test.cpp) with its paw nested.
  const parts = JSON.stringify({ parts: [{ name: 'front leg', source: { disk: { seed: 1449, radius: 0.2 } },
    children: [{ name: 'paw', source: { disk: { seed: 1449, radius: 0.08 } } }] }] });
  const { buffers, info } = ops.partTransfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', parts, partOptions: { seam_rings: 3 } });
  const n = ctx.state.meshes.get('source').weldedPositions.length;
  assert.equal(buffers.positions.length, n);
  assert.equal(buffers.positionsLevel1.length, n);
  assert.deepEqual(info.parts.map((p) => [p.name, p.level]), [['front leg', 2], ['paw', 3]]);
  assert.ok(info.level1.k > 0 && info.level1.gamma.length === info.level1.k ** 2 && Number.isFinite(info.level1.gammaDominance));
  // Labels: the paw (deepest) inside the leg, the rest of the lion outside both.
  const count = (label) => buffers.partLabels.filter((l) => l === label).length;
  assert.ok(count(1) > 0 && count(0) > 0 && count(-1) > n / 3 / 2, `labels: leg ${count(0)}, paw ${count(1)}, none ${count(-1)}`);
  assert.equal(count(0) + count(1), info.parts[0].sourceVertexCount);
  assert.equal(count(1), info.parts[1].sourceVertexCount);
  // A kept part moved its vertices; the rest stayed at level 1.
  let movedInside = 0, movedOutside = 0;
  for (let v = 0; v < n / 3; ++v) {
    const d = Math.hypot(...[0, 1, 2].map((k) => buffers.positions[3 * v + k] - buffers.positionsLevel1[3 * v + k]));
    if (buffers.partLabels[v] >= 0) movedInside = Math.max(movedInside, d);
    else movedOutside = Math.max(movedOutside, d);
  }
  if (info.parts.some((p) => p.ok && !p.rejected)) assert.ok(movedInside > 1e-4, `no part vertex moved (${movedInside})`);
  assert.deepEqual(JSON.parse(info.partsJson).parts.map((p) => p.name), ['front leg']);
  for (const key of ['reference', 'source', 'level1', 'result', 'flipsLevel1', 'flips']) assert.ok(Number.isInteger(info.folds[key]), key);
  assert.ok(info.ms.total >= info.ms.level1);
  expectCode(() => ops.partTransfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', parts: '{"parts": [{"source": {"disk": {"seed": 99999, "radius": 0.1}}}]}' }), 'InvalidArgument');
});

test('landmark clicks pair a reference vertex with a source vertex in either order', () => {
  const l = new LandmarkPairs();
  assert.equal(l.click('reference', 3), 'pending');
  assert.equal(l.click('reference', 4), 'pending'); // moves the waiting half
  assert.equal(l.click('source', 9), 'paired');
  assert.equal(l.click('source', 1), 'pending');
  assert.equal(l.click('reference', 2), 'paired');
  assert.deepEqual(l.pairs, [[4, 9], [2, 1]]);
  l.move(1, 'source', 7); // a selected pair's end clicked elsewhere
  l.move(1, 'reference', 5);
  l.move(2, 'reference', 8); // no such pair: nothing changes
  assert.deepEqual(l.pairs, [[4, 9], [5, 7]]);
  l.remove(0);
  assert.deepEqual(l.pairs, [[5, 7]]);
});
