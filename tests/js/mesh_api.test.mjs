// API tests of wasm/bind_mesh.cpp through web/src/worker/ops/mesh.js — the functions the worker runs —
// with the node build of the module. Run: node --test tests/js/ (MM_WASM_DIR overrides the
// build directory).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { ops } from '../../web/src/worker/ops/mesh.js';
import { dataBytes, fileBuffers, makeContext, readGolden } from './wasm_module.mjs';

const encoder = new TextEncoder();

// A unit tetrahedron as OBJ text; outward-facing, closed.
const tetraObj = ['v 0 0 0', 'v 1 0 0', 'v 0 1 0', 'v 0 0 1', 'f 1 3 2', 'f 1 2 4', 'f 1 4 3', 'f 2 3 4', ''].join('\n');

function expectCode(fn, code, messagePattern) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof MeshMorphError, `expected a MeshMorphError, got ${e}`);
    assert.equal(e.code, code, `code of "${e.message}"`);
    if (messagePattern) assert.match(e.message, messagePattern);
    return true;
  });
}

// Surface area from the welded arrays: the lumped Voronoi mass sums to it, and the C++ golden
// stores λ·area (tests/spectral_test.cpp, GoldenEigenvaluesOfRealMeshes).
function surfaceArea(V, F) {
  let area = 0;
  for (let f = 0; f < F.length; f += 3) {
    const [a, b, c] = [F[f] * 3, F[f + 1] * 3, F[f + 2] * 3];
    const u = [V[b] - V[a], V[b + 1] - V[a + 1], V[b + 2] - V[a + 2]];
    const v = [V[c] - V[a], V[c + 1] - V[a + 1], V[c + 2] - V[a + 2]];
    const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    area += 0.5 * Math.hypot(...n);
  }
  return area;
}

test('load a PLY: counts, layouts and the info report', async () => {
  const ctx = await makeContext();
  const { buffers, info } = ops.load(ctx, { name: 'skull.ply' }, fileBuffers('edit/skull.ply'));
  assert.equal(info.format.toLowerCase(), 'ply');
  assert.equal(info.rawVertices, 5154);
  assert.equal(buffers.positions.length, 5154 * 3);
  assert.equal(buffers.indices.length, 10312 * 3);
  assert.equal(buffers.normals.length, buffers.positions.length);
  assert.ok(buffers.positions instanceof Float32Array && buffers.indices instanceof Uint32Array);
  assert.equal(buffers.toWelded.length, 5154);
  assert.ok(Math.max(...buffers.toWelded) < info.weldedVertices);
  assert.equal(info.report.faces, 10312);
  assert.equal(info.report.defects.length, 0, JSON.stringify(info.report.defects));
  assert.equal(info.report.components, 1);
  // The same report as `meshmorph info` (io/info_report.h): text and JSON agree.
  assert.match(info.text, /skull\.ply/);
  assert.match(info.text, /vertices: \d+/);
  assert.equal(info.infoReport.file, 'skull.ply');
  assert.equal(info.infoReport.welded.faces, 10312);
  // Normals are unit length (smooth normals of the welded surface).
  for (let i = 0; i < 30; i += 3) assert.ok(Math.abs(Math.hypot(...buffers.normals.subarray(i, i + 3)) - 1) < 1e-5);
  assert.ok(ctx.state.meshes.get('main'));
});

test('load an OBJ from memory; a second load replaces the slot and frees the first asset', async () => {
  const ctx = await makeContext();
  const first = ops.load(ctx, { name: 'tetra.obj' }, { 'tetra.obj': encoder.encode(tetraObj) });
  assert.equal(first.info.weldedVertices, 4);
  assert.equal(first.info.report.closed, true);
  assert.equal(first.info.report.eulerCharacteristic, 2);
  const firstAsset = ctx.state.meshes.get('main').asset;
  ops.load(ctx, { name: 'tetra.obj' }, { 'tetra.obj': encoder.encode(tetraObj) });
  assert.notEqual(ctx.state.meshes.get('main').asset, firstAsset);
  assert.equal(ctx.module.disposeAsset(firstAsset), false, 'the replaced asset was disposed');
  // Slots are independent (transfer/retarget load a second mesh).
  ops.load(ctx, { name: 'hand.ply', slot: 'reference' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') });
  assert.equal(ctx.state.meshes.get('main').name, 'tetra.obj');
  assert.equal(ctx.state.meshes.get('reference').weldedPositions.length, 810 * 3);
  assert.deepEqual(ops.unload(ctx, { slot: 'reference' }).info, { slot: 'reference', unloaded: true });
});

test('malformed files give readable errors and the module keeps working', async () => {
  const ctx = await makeContext();
  const garbage = new Uint8Array(4096).map((_, i) => (i * 7919) % 251);
  expectCode(() => ops.load(ctx, { name: 'garbage.glb' }, { 'garbage.glb': garbage }), 'ParseError');
  const truncated = dataBytes('edit/skull.ply').slice(0, 20000);
  expectCode(() => ops.load(ctx, { name: 'cut.ply' }, { 'cut.ply': truncated }), 'ParseError', /\S/);
  expectCode(() => ops.load(ctx, { name: 'bad.obj' }, { 'bad.obj': encoder.encode('v 0 0 0\nf 1 2 3\n') }), 'ParseError');
  expectCode(() => ops.load(ctx, { name: 'empty.off' }, { 'empty.off': new Uint8Array(0) }), 'ParseError', /empty/);
  expectCode(() => ops.load(ctx, { name: 'mesh.xyz' }, { 'mesh.xyz': encoder.encode('1 2 3') }), 'Unsupported', /\.glb/);
  expectCode(() => ops.eigs(ctx, { k: 5 }), 'InvalidArgument', /no mesh is loaded/);
  // Still usable after the failures.
  const { info } = ops.load(ctx, { name: 'tetra.obj' }, { 'tetra.obj': encoder.encode(tetraObj) });
  assert.equal(info.weldedVertices, 4);
});

test('eigenbasis of the skull matches the C++ golden (spectral_eigs_skull: λ·area, k = 20)', async () => {
  const ctx = await makeContext();
  ops.load(ctx, { name: 'skull.ply' }, fileBuffers('edit/skull.ply'));
  const fractions = [];
  const progressCtx = { ...ctx, progress: (stage, f) => { fractions.push(f); return true; } };
  const { buffers, info } = ops.eigs(progressCtx, { k: 20 });
  assert.equal(info.k, 20);
  const mesh = ctx.state.meshes.get('main');
  const n = mesh.weldedPositions.length / 3;
  assert.equal(buffers.vectors.length, 20 * n);
  assert.ok(buffers.eigenvalues instanceof Float64Array && buffers.vectors instanceof Float32Array);
  assert.ok(fractions.length > 0 && fractions.every((f) => f >= 0 && f <= 1), 'progress reported in 0..1');
  for (let i = 1; i < 20; ++i) assert.ok(buffers.eigenvalues[i] >= buffers.eigenvalues[i - 1]);

  const golden = readGolden('spectral_eigs_skull');
  assert.equal(golden.rows, 20);
  assert.equal(golden.cols, 1);
  const area = surfaceArea(mesh.weldedPositions, mesh.weldedIndices);
  let worst = 0;
  for (let i = 0; i < 20; ++i) worst = Math.max(worst, Math.abs(buffers.eigenvalues[i] * area - golden.data[i]));
  assert.ok(worst <= golden.tolerance, `largest difference ${worst} > tolerance ${golden.tolerance}`);
});

test('eigenbasis: the block Lanczos gives the skull golden too, reports progress and cancels', async () => {
  const ctx = await makeContext();
  ops.load(ctx, { name: 'skull.ply' }, fileBuffers('edit/skull.ply'));
  const mesh = ctx.state.meshes.get('main');
  const area = surfaceArea(mesh.weldedPositions, mesh.weldedIndices);
  const golden = readGolden('spectral_eigs_skull');
  const fractions = [];
  const progressCtx = { ...ctx, progress: (stage, f) => { fractions.push(f); return true; } };
  const block = ops.eigs(progressCtx, { k: 20, solver: 'block' });
  const spectra = ops.eigs(ctx, { k: 20, solver: 'spectra' });
  assert.equal(block.info.solver, 'block Lanczos');
  assert.equal(spectra.info.solver, 'Spectra');
  assert.ok(block.info.operations > spectra.info.operations, 'the block solver applies more vectors');
  let worst = 0, apart = 0;
  for (let i = 0; i < 20; ++i) {
    worst = Math.max(worst, Math.abs(block.buffers.eigenvalues[i] * area - golden.data[i]));
    apart = Math.max(apart, Math.abs(block.buffers.eigenvalues[i] - spectra.buffers.eigenvalues[i]) / (1 + spectra.buffers.eigenvalues[i]));
  }
  assert.ok(worst <= golden.tolerance, `largest difference ${worst} > tolerance ${golden.tolerance}`);
  assert.ok(apart < 1e-10, `block and Spectra eigenvalues ${apart} apart`);
  assert.ok(fractions.length > 3 && fractions.every((f) => f >= 0 && f <= 1));
  let calls = 0;
  expectCode(() => ops.eigs({ ...ctx, progress: () => ++calls < 4 }, { k: 20, solver: 'block' }), 'Cancelled');
  assert.equal(calls, 4);
  expectCode(() => ops.eigs(ctx, { k: 20, solver: 'lobpcg' }), 'InvalidArgument', /solver must be/);
});

test('eigenbasis: cancel through the progress callback, bad k, non-manifold input', async () => {
  const ctx = await makeContext();
  ops.load(ctx, { name: 'hand.ply' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') });
  let calls = 0;
  const cancelling = { ...ctx, progress: () => ++calls < 3 };
  expectCode(() => ops.eigs(cancelling, { k: 10 }), 'Cancelled');
  assert.equal(calls, 3);
  expectCode(() => ops.eigs(ctx, { k: 5000 }), 'InvalidArgument', /need 1 <= k < #V/);
  // After a cancel the same asset still computes.
  const { buffers } = ops.eigs(ctx, { k: 6 });
  assert.ok(Math.abs(buffers.eigenvalues[0]) < 1e-6);

  // Three triangles on one edge: refused with the validator's message.
  const V = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1]);
  const F = new Uint32Array([0, 1, 2, 1, 0, 3, 0, 1, 4]);
  const r = ctx.module.spectralBasis(V, F, { k: 2 }, undefined);
  assert.equal(r.ok, false);
  assert.equal(r.code, 'InvalidMesh');
  assert.match(r.message, /non-manifold/i);
});

test('validate arrays: defects are counted with a first example', async () => {
  const ctx = await makeContext();
  const positions = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, NaN, 0, 0]);
  const indices = new Uint32Array([0, 1, 2, 1, 0, 3, 0, 1, 4, 0, 1, 9]);
  const { info } = ops.validate(ctx, {}, { positions, indices });
  const names = info.report.defects.map((d) => d.id);
  for (const expected of ['NonFiniteCoordinate', 'IndexOutOfRange']) assert.ok(names.includes(expected), names.join(', '));
  const range = info.report.defects.find((d) => d.id === 'IndexOutOfRange');
  assert.equal(range.count, 1);
  assert.match(range.example, /face 3/);
  assert.match(info.text, /defects:/);
});

test('export GLB: a valid GLB container that loads back with the same geometry', async () => {
  const ctx = await makeContext();
  const loaded = ops.load(ctx, { name: 'hand.ply' }, { 'hand.ply': dataBytes('edit/hand_lowres.ply') });
  const { buffers, info } = ops.export(ctx, { format: 'glb' });
  assert.equal(info.fileName, 'hand.glb');
  const bytes = buffers.bytes;
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  assert.equal(new TextDecoder().decode(bytes.subarray(0, 4)), 'glTF');
  assert.equal(view.getUint32(4, true), 2, 'glTF version 2');
  assert.equal(view.getUint32(8, true), bytes.length, 'header length = file length');
  const back = ops.load(ctx, { name: 'hand.glb', slot: 'back' }, { 'hand.glb': bytes });
  assert.equal(back.info.weldedVertices, loaded.info.weldedVertices);
  assert.equal(back.info.report.faces, loaded.info.report.faces);

  // New positions must match the welded vertex count.
  expectCode(() => ops.export(ctx, { format: 'glb' }, { positions: new Float64Array(9) }), 'InvalidArgument', /welded vertices/);
  // Moved positions are written.
  const moved = ctx.state.meshes.get('main').weldedPositions.map((x) => x * 2);
  const scaled = ops.export(ctx, { format: 'glb' }, { positions: moved });
  const again = ops.load(ctx, { name: 'scaled.glb', slot: 'back' }, { 'scaled.glb': scaled.buffers.bytes });
  assert.ok(Math.abs(again.info.report.bboxDiagonal - 2 * loaded.info.report.bboxDiagonal) < 1e-4 * loaded.info.report.bboxDiagonal);
});

test('.gltf with its .bin and image passed as sibling files', async () => {
  const ctx = await makeContext();
  const buffers = fileBuffers('anim/Fox/glTF/Fox.gltf', ['Fox.bin', 'Texture.png']);
  const { info } = ops.load(ctx, { name: 'Fox.gltf' }, buffers);
  assert.equal(info.format.toLowerCase(), 'gltf');
  assert.ok(info.weldedVertices > 0 && info.weldedVertices <= info.rawVertices);
  assert.equal(info.primitives.length, 1);
  assert.equal(info.primitives[0].skinned, true);
  // Without its .bin the file cannot load: IoError naming the missing buffer.
  expectCode(() => ops.load(ctx, { name: 'Fox.gltf' }, { 'Fox.gltf': buffers['Fox.gltf'] }), 'IoError', /Fox\.bin/);
});
