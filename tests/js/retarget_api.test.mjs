// API tests of wasm/bind_retarget.cpp through web/src/worker/ops/retarget.js — the functions the worker
// runs — with the node build of the module: Fox (Walk) → wolf0 with placed joints (paper 002).
// Run: node --test tests/js/ (MM_WASM_DIR overrides the build directory).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { ops } from '../../web/src/worker/ops/retarget.js';
import { dataBytes, makeContext } from './wasm_module.mjs';

const jointsJson = new TextDecoder().decode(dataBytes('joints/wolf0_joints.json'));

function prepare(ctx, extra = {}) {
  return ops.retargetPrepare(
    ctx,
    { sourceName: 'Fox.glb', targetName: 'wolf0.ply', targetJointsJson: jointsJson, clip: 'Walk', fps: 15,
      first_frame: 0, last_frame: 5,  // frames [0, 5)
      ...extra },
    { source: dataBytes('anim/Fox/glTF-Binary/Fox.glb'), target: dataBytes('anim/wolf0.ply') });
}

// Plays the exported GLB the way the page would (three.js GLTFLoader + AnimationMixer) and
// returns sampled vertex positions (morph targets applied) at the given times.
async function playGlb(bytes, times) {
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(ab, '', resolve, reject));
  assert.equal(gltf.animations.length, 1);
  let mesh = null;
  gltf.scene.traverse((o) => {
    if (o.isMesh && o.morphTargetInfluences) mesh = o;
  });
  assert.ok(mesh, 'a mesh with morph targets');
  const mixer = new THREE.AnimationMixer(gltf.scene);
  mixer.clipAction(gltf.animations[0]).play();
  const v = new THREE.Vector3();
  return times.map((t) => {
    mixer.setTime(t);
    const out = [];
    for (let i = 0; i < mesh.geometry.attributes.position.count; i += 25) out.push(mesh.getVertexPosition(i, v).clone());
    return { positions: out, weights: Array.from(mesh.morphTargetInfluences) };
  });
}

function maxFrameDelta(positions, nv, a, b) {
  let d = 0;
  for (let i = 0; i < nv * 3; ++i) d = Math.max(d, Math.abs(positions[a * nv * 3 + i] - positions[b * nv * 3 + i]));
  return d;
}

test('Fox → wolf0: precompute, frames in batches with progress, export', async () => {
  const events = [];
  const ctx = await makeContext((stage, f) => {
    events.push([stage, f]);
    return true;
  });
  const { info, buffers } = prepare(ctx);
  assert.ok(info.session > 0);
  assert.equal(info.clip, 'Walk');
  assert.equal(info.frames, 5);
  assert.equal(buffers.times.length, 5);
  const nv = buffers.targetPositions.length / 3;
  assert.ok(nv > 1000 && Number.isInteger(nv), `wolf0 vertices: ${nv}`);
  assert.equal(buffers.targetIndices.length % 3, 0);
  // Precompute reports its stages with fractions in [0, 1].
  const stages = new Set(events.map(([s]) => s));
  for (const s of ['singularities', 'collocation', 'svd']) assert.ok(stages.has(s), `stage ${s} in ${[...stages]}`);
  for (const [, f] of events) assert.ok(f >= 0 && f <= 1, `progress ${f}`);

  // Two batches: 0..2 and 3..4, progress per frame ending at 1.
  events.length = 0;
  const a = ops.retargetFrames(ctx, { session: info.session, first: 0, count: 3 });
  assert.equal(a.info.count, 3);
  const frameEvents = events.filter(([s]) => s === 'frames');
  assert.ok(frameEvents.length >= 3, `frame progress events: ${frameEvents.length}`);
  assert.equal(frameEvents.at(-1)[1], 1);
  const b = ops.retargetFrames(ctx, { session: info.session, first: 3 });
  assert.equal(b.info.count, 2);
  const all = new Float32Array(5 * nv * 3);
  all.set(a.buffers.positions, 0);
  all.set(b.buffers.positions, 3 * nv * 3);
  assert.ok(all.every(Number.isFinite), 'all positions finite');

  // The character moves between frames, but stays near its rest shape (wolf0 is ~190 units).
  let extent = 0;
  for (let c = 0; c < 3; ++c) {
    let lo = Infinity, hi = -Infinity;
    for (let i = c; i < buffers.targetPositions.length; i += 3) {
      lo = Math.min(lo, buffers.targetPositions[i]);
      hi = Math.max(hi, buffers.targetPositions[i]);
    }
    extent = Math.max(extent, hi - lo);
  }
  for (let k = 1; k < 5; ++k) {
    const d = maxFrameDelta(all, nv, k - 1, k);
    assert.ok(d > 1e-3 * extent, `frame ${k - 1} → ${k} moves (max delta ${d})`);
  }
  for (let k = 0; k < 5; ++k) {
    let worst = 0;
    for (let i = 0; i < nv * 3; ++i)
      worst = Math.max(worst, Math.abs(all[k * nv * 3 + i] - buffers.targetPositions[i]));
    assert.ok(worst < 0.5 * extent, `frame ${k} stays near the rest shape (max offset ${worst})`);
  }

  // Export: a GLB (magic "glTF") holding the morph animation.
  const glb = ops.retargetExportGlb(ctx, { session: info.session }, { positions: all });
  const bytes = glb.buffers.bytes;
  assert.ok(bytes.length > 12);
  assert.equal(new TextDecoder().decode(bytes.subarray(0, 4)), 'glTF');
  // three.js plays it: the weights animation blends neighbouring frames and the surface moves.
  const [p0, p1] = await playGlb(bytes, [buffers.times[1], buffers.times[3]]);
  assert.equal(p0.weights.length, 5);
  assert.ok(Math.abs(p0.weights.reduce((s, w) => s + w, 0) - 1) < 1e-6, `weights ${p0.weights}`);
  assert.ok(p0.weights[1] > 0.99, `frame 1 fully on at its time: ${p0.weights}`);
  let moved = 0;
  for (let i = 0; i < p0.positions.length; ++i) moved = Math.max(moved, p0.positions[i].distanceTo(p1.positions[i]));
  assert.ok(moved > 1e-3 * extent, `playback moves between two times (max ${moved})`);
  // Positions that are not whole frames of the target are an InvalidArgument.
  assert.throws(() => ops.retargetExportGlb(ctx, { session: info.session }, { positions: all.subarray(1) }),
    (e) => e instanceof MeshMorphError && e.code === 'InvalidArgument');

  assert.equal(ops.retargetDispose(ctx, { session: info.session }).info.disposed, true);
  assert.throws(() => ops.retargetFrames(ctx, { session: info.session, first: 0, count: 1 }),
    (e) => e instanceof MeshMorphError && e.code === 'InvalidArgument');
});

test('cancel: progress returning false stops precompute and frames with Cancelled', async () => {
  let cancelStage = 'svd';
  const ctx = await makeContext((stage) => stage !== cancelStage);
  assert.throws(() => prepare(ctx), (e) => e instanceof MeshMorphError && e.code === 'Cancelled');
  assert.equal(ctx.state.retarget?.size ?? 0, 0, 'no session kept after a cancelled precompute');

  cancelStage = 'frames';
  const { info } = prepare(ctx);
  assert.throws(() => ops.retargetFrames(ctx, { session: info.session, first: 0, count: 2 }),
    (e) => e instanceof MeshMorphError && e.code === 'Cancelled');
  // The session survives a cancelled batch.
  cancelStage = 'none';
  const r = ops.retargetFrames(ctx, { session: info.session, first: 0, count: 1 });
  assert.equal(r.info.count, 1);
  ops.retargetDispose(ctx, { session: info.session });
});

test('errors: unknown clip lists the clips, PLY target without joints', async () => {
  const ctx = await makeContext();
  assert.throws(() => prepare(ctx, { clip: 'Gallop' }),
    (e) => e instanceof MeshMorphError && e.code === 'InvalidArgument' && /Survey/.test(e.message));
  assert.throws(() => prepare(ctx, { targetJointsJson: '' }),
    (e) => e instanceof MeshMorphError && e.code === 'InvalidArgument');
});
