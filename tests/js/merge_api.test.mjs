// API tests of the Merge job's worker ops (web/src/worker/ops/merge.js over wasm/bind_merge.cpp)
// with the node build of the module, and of the page's merge helpers (web/src/lib/merge-spec.js,
// web/src/lib/merge-geometry.js) on the bundled pair: the TOSCA horse cut at the neck (the
// plane of data/specs/merge-camelhead-horse.json) and the camel's head.
// Run: node --test tests/js/ (MM_WASM_DIR overrides the build directory).
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { edgeDistances, loopFrame, placeOnLoop, planeRemoves, randomSimilarity } from '../../web/src/lib/merge-geometry.js';
import { KeyPairs, buildMergeSpec, keyPairsProblem, readMergeSpec } from '../../web/src/lib/merge-spec.js';
import { vertexAdjacency } from '../../web/src/lib/vertex-sets.js';
import { ops as meshOps } from '../../web/src/worker/ops/mesh.js';
import { ops } from '../../web/src/worker/ops/merge.js';
import { fileBuffers, makeContext, repoDir } from './wasm_module.mjs';

const exampleSpec = JSON.parse(fs.readFileSync(path.join(repoDir, 'data/specs/merge-camelhead-horse.json'), 'utf8'));
const neckCut = { plane: [0, -85, 140, 0, -1, 1], keep: [0, 0, 100] };

function expectCode(fn, code, pattern) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof MeshMorphError, `expected a MeshMorphError, got ${e}`);
    assert.equal(e.code, code, `code of "${e.message}"`);
    if (pattern) assert.match(e.message, pattern);
    return true;
  });
}

async function examplePair(ctx) {
  const target = ops.mergeOpen(ctx, { slot: 't', name: 'horse0.ply', cuts: [neckCut] }, fileBuffers('pose/horse0.ply'));
  const source = ops.mergeOpen(ctx, { slot: 's', name: 'camelhead.ply' }, fileBuffers('edit/camelhead.ply'));
  return { target, source };
}

const maxDifference = (a, b) => {
  let max = 0;
  for (let i = 0; i < a.length; i += 3) max = Math.max(max, Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
  return max;
};

test('mergeOpen cuts the horse open at the neck like `meshmorph cut` and lists the loops', async () => {
  const ctx = await makeContext();
  const { target, source } = await examplePair(ctx);
  // data/specs/merge-camelhead-horse.json: the cut horse has 13102 vertices, one loop.
  assert.equal(target.info.weldedVertices, 13102);
  assert.equal(target.info.loops.length, 1);
  assert.equal(target.info.cuts.length, 1);
  assert.deepEqual(target.info.cuts[0], { vertices: 13102, faces: 26091, boundaryLoops: 1 });
  // The spec's keys are on the loops.
  for (const k of exampleSpec.pairs[0].target_keys) assert.ok(target.info.loops[0].includes(k), `target key ${k}`);
  assert.equal(source.info.loops.length, 1);
  assert.equal(source.info.loops[0].length, 56);
  for (const k of exampleSpec.pairs[0].source_keys) assert.ok(source.info.loops[0].includes(k), `source key ${k}`);
  // Display buffers of a cut mesh are its welded mesh (identity map).
  assert.equal(target.buffers.positions.length, 13102 * 3);
  assert.ok(target.buffers.toWelded.every((w, r) => w === r));
  assert.equal(target.buffers.welded.length, 13102 * 3);
  // The horse as a whole is closed.
  const closed = ops.mergeOpen(ctx, { slot: 'c', name: 'horse0.ply' }, fileBuffers('pose/horse0.ply'));
  assert.equal(closed.info.loops.length, 0);
  // A bad cut is a readable error and leaves no half-cut slot.
  expectCode(() => ops.mergeOpen(ctx, { slot: 'c', name: 'horse0.ply', cuts: [{ disk: [5, -1] }] }, fileBuffers('pose/horse0.ply')), 'InvalidArgument', /cut 1/);
  assert.equal(ctx.state.meshes.has('c'), false);
  expectCode(() => ops.mergeOpen(ctx, { slot: 'c', name: 'horse0.ply', cuts: [{ plane: [0, 0] }] }, fileBuffers('pose/horse0.ply')), 'InvalidArgument', /plane/);
});

test('merge of the bundled pair: watertight, seam report, errors from the core are readable', async () => {
  const ctx = await makeContext();
  await examplePair(ctx);
  const progress = [];
  ctx.progress = (stage, fraction) => { progress.push([stage, fraction]); return true; };
  const { buffers, info } = ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: exampleSpec });
  assert.equal(info.boundaryLoops, 0);
  assert.equal(info.vertices, buffers.positions.length / 3);
  assert.ok(buffers.positions instanceof Float64Array);
  assert.equal(info.seams.length, 1);
  const seam = info.seams[0];
  assert.ok(seam.zipFaces > 0 && seam.flippedFaces === 0 && seam.minAngleDeg > 0, JSON.stringify(seam));
  assert.ok(Number.isFinite(seam.dihedralMaxDeg) && Number.isFinite(seam.dihedralMeanDeg));
  assert.ok(progress.length > 0, 'no progress reported');
  // Cancel through the progress sink.
  ctx.progress = () => false;
  expectCode(() => ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: exampleSpec }), 'Cancelled');
  ctx.progress = () => true;
  // Errors: too few keys, keys out of order, a closed source, a key off the boundary.
  const pair = exampleSpec.pairs[0];
  expectCode(() => ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: { pairs: [{ target_keys: [pair.target_keys[0]], source_keys: [pair.source_keys[0]] }] } }), 'InvalidArgument', /two|2/);
  const loopT = ctx.state.meshes.get('t');
  assert.ok(loopT);
  ops.mergeOpen(ctx, { slot: 'closed', name: 'horse0.ply' }, fileBuffers('pose/horse0.ply'));
  expectCode(() => ops.merge(ctx, { targetSlot: 't', sourceSlot: 'closed', spec: exampleSpec }), 'InvalidMesh', /no boundary/);
  expectCode(() => ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: { pairs: [{ target_keys: [0, 1], source_keys: pair.source_keys }] } }), 'InvalidArgument', /not on/);
  expectCode(() => ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: { pairs: exampleSpec.pairs, bogus: 1 } }), 'ParseError', /unknown key/);
  // The result as GLB in the target's document loads back with the merged vertex count.
  const glb = ops.mergeExport(ctx, { slot: 't', format: 'glb' }, { positions: buffers.positions, indices: buffers.indices });
  assert.equal(Buffer.from(glb.buffers.bytes.subarray(0, 4)).toString('latin1'), 'glTF');
  const back = meshOps.load(ctx, { name: 'merged.glb', slot: 'back' }, { 'merged.glb': glb.buffers.bytes });
  assert.equal(back.info.weldedVertices, info.vertices);
  assert.equal(back.info.report.boundaryLoopLengths.length, 0);
});

test('configuration independence: a similarity on the source gives the same merged mesh', async () => {
  const ctx = await makeContext();
  await examplePair(ctx);
  const base = ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: exampleSpec });
  let seed = 7;
  const random = () => { seed = (seed * 16807) % 2147483647; return seed / 2147483647; };
  const moved = ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec: exampleSpec, placement: randomSimilarity(300, random) });
  assert.equal(moved.buffers.positions.length, base.buffers.positions.length);
  const diagonal = 334.771;
  const error = maxDifference(moved.buffers.positions, base.buffers.positions) / diagonal;
  // The core's WIP note: 1e-6 today, 1e-9 once the editor's precision work lands.
  assert.ok(error < 1e-5, `moved source changes the result by ${error}·diag`);
  // The placed source saved as OFF (full precision) holds the moved coordinates.
  const off = ops.mergeExport(ctx, { slot: 's', format: 'off', placement: randomSimilarity(1, random) });
  assert.match(Buffer.from(off.buffers.bytes.subarray(0, 3)).toString('latin1'), /OFF/);
});

test('dependent mode keeps fixed handles and vertices outside the band', async () => {
  const ctx = await makeContext();
  const { target, source } = await examplePair(ctx);
  const placement = placeOnLoop(target.buffers.welded, target.info.loops[0], source.buffers.welded, source.info.loops[0],
    [exampleSpec.pairs[0].target_keys[0], exampleSpec.pairs[0].source_keys[0]]);
  // The camel's nose tip (furthest from the neck loop) is fixed.
  const s = source.buffers.welded;
  const frame = loopFrame(s, source.info.loops[0]);
  let tip = 0;
  let far = -1;
  for (let v = 0; v < s.length / 3; ++v) {
    const d = Math.hypot(s[3 * v] - frame.centre[0], s[3 * v + 1] - frame.centre[1], s[3 * v + 2] - frame.centre[2]);
    if (d > far) { far = d; tip = v; }
  }
  const spec = { ...exampleSpec, fixed: [tip], options: { mode: 'dependent' } };
  delete spec.comment;
  const { buffers, info } = ops.merge(ctx, { targetSlot: 't', sourceSlot: 's', spec, placement });
  assert.equal(info.boundaryLoops, 0);
  const m = placement;
  const placed = [0, 1, 2].map((i) => m[i] * s[3 * tip] + m[4 + i] * s[3 * tip + 1] + m[8 + i] * s[3 * tip + 2] + m[12 + i]);
  const got = [0, 1, 2].map((i) => buffers.positions[3 * (info.sourceOffset + tip) + i]);
  assert.ok(Math.hypot(...placed.map((v, i) => v - got[i])) < 1e-9 * 334, `fixed tip moved: ${placed} → ${got}`);
});

test('page helpers: key pairs, spec file, order check, cut previews, loop placement', () => {
  const keys = new KeyPairs();
  assert.equal(keys.click('source', 5), 'pending');
  assert.equal(keys.click('source', 6), 'pending');
  assert.equal(keys.click('target', 1), 'paired');
  keys.click('target', 2);
  keys.click('source', 7);
  keys.click('target', 3);
  keys.click('source', 8);
  assert.deepEqual(keys.pairs, [[1, 6], [2, 7], [3, 8]]);
  assert.equal(keys.move(2, -1), 1);
  assert.deepEqual(keys.pairs, [[1, 6], [3, 8], [2, 7]]);
  assert.equal(keys.move(0, -1), 0);

  const spec = buildMergeSpec({ pairs: [[13035, 9788], [8349, 9775]], options: { mode: 'dependent' }, fixed: [4], comment: 'c' });
  assert.deepEqual(spec, { comment: 'c', pairs: [{ target_keys: [13035, 8349], source_keys: [9788, 9775] }], fixed: [4], options: { mode: 'dependent' } });
  const read = readMergeSpec(spec, { targetVertices: 13102, sourceVertices: 11381 });
  assert.deepEqual(read.pairs, [[13035, 9788], [8349, 9775]]);
  assert.deepEqual(read.fixed, [4]);
  assert.deepEqual(readMergeSpec(exampleSpec).pairs, [[13035, 9788], [8349, 9775]]);
  assert.throws(() => readMergeSpec({ ...spec, extra: 1 }), /unknown key "extra"/);
  assert.throws(() => readMergeSpec(spec, { targetVertices: 100, sourceVertices: 11381 }), /13035.*100 vertices/);
  assert.throws(() => readMergeSpec({ pairs: [spec.pairs[0], spec.pairs[0]] }), /one/);
  assert.throws(() => readMergeSpec({ pairs: [{ target_keys: [1, 2], source_keys: [3] }] }), /pairs/);

  // Loops: target 0..7 in order; the source loop runs the other way round.
  const t = [0, 1, 2, 3, 4, 5, 6, 7];
  const s = [10, 11, 12, 13, 14, 15];
  assert.match(keyPairsProblem([[0, 10]], t, s), /at least 2/);
  assert.equal(keyPairsProblem([[0, 10], [3, 13]], t, s), null);
  assert.equal(keyPairsProblem([[0, 15], [2, 13], [5, 11]], t, s), null);
  assert.match(keyPairsProblem([[0, 11], [2, 13], [5, 15]], t, s), /out of order/);
  assert.match(keyPairsProblem([[0, 10], [9, 13]], t, s), /not on the chosen target loop/);
  assert.match(keyPairsProblem([[0, 10], [0, 13]], t, s), /same target vertex/);

  // A plane removes the side its normal does not point to.
  const square = new Float64Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]);
  assert.deepEqual([...planeRemoves(square, [0.5, 0, 0], [1, 0, 0])], [1, 0, 0, 1]);
  const adjacency = vertexAdjacency(new Uint32Array([0, 1, 2, 0, 2, 3]), 4);
  const d = edgeDistances(square, adjacency, 0);
  assert.deepEqual([...d].map((x) => Number(x.toFixed(6))), [0, 1, Number(Math.SQRT2.toFixed(6)), 1]);

  // placeOnLoop: a loop and its copy moved by a similarity (and reversed, facing the other
  // way, as a source continuing out of the target's opening) are put back on each other.
  const ring = (n, r, z) => Array.from({ length: n }, (_, i) => [r * Math.cos((2 * Math.PI * i) / n), r * Math.sin((2 * Math.PI * i) / n), z]).flat();
  const target = new Float64Array(ring(12, 2, 0));
  const targetLoop = [...Array(12).keys()];
  // The source: the same ring, traversed the other way, scaled by 0.5 and shifted.
  const source = new Float64Array(ring(12, 1, 0).map((v, i) => (i % 3 === 0 ? v + 5 : v)));
  const sourceLoop = [0, ...[...Array(11).keys()].map((i) => 11 - i)];
  const m = placeOnLoop(target, targetLoop, source, sourceLoop, [0, 0]);
  const apply = (p) => [0, 1, 2].map((i) => m[i] * p[0] + m[4 + i] * p[1] + m[8 + i] * p[2] + m[12 + i]);
  for (let v = 0; v < 12; ++v) {
    const q = apply([source[3 * v], source[3 * v + 1], source[3 * v + 2]]);
    const err = Math.hypot(q[0] - target[3 * v], q[1] - target[3 * v + 1], q[2] - target[3 * v + 2]);
    assert.ok(err < 1e-9, `vertex ${v} lands ${err} away`);
  }
  assert.ok(Math.abs(loopFrame(target, targetLoop).length - 12 * 2 * 2 * Math.sin(Math.PI / 12)) < 1e-9);
});
