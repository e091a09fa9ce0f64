// The compact morph export (issue 15) played by three.js: retarget_compact_fox.glb and
// retarget_frames_fox.glb, which tests/morph_export_test.cpp (MorphExport.CompactLongFox*) writes
// to the scratch folder, are loaded with GLTFLoader and played with an AnimationMixer; at keys and
// between keys every vertex of the compact file (KHR_mesh_quantization SHORT components, weights
// carrying their scale) is within the export tolerance (1e-3 of the size) of the per-frame file.
//   MM_SCRATCH_DIR=<build>/tests/test-scratch node --test tests/js/morph_export.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

const scratch = process.env.MM_SCRATCH_DIR;
const compactFile = scratch && path.join(scratch, 'retarget_compact_fox.glb');
const framesFile = scratch && path.join(scratch, 'retarget_frames_fox.glb');
const present = compactFile && fs.existsSync(compactFile) && fs.existsSync(framesFile);

async function open(file) {
  const b = fs.readFileSync(file);
  const ab = b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength);
  // No images under node (the Fox's texture needs a browser): textures load as none.
  const loader = new GLTFLoader().register(() => ({ name: 'no_textures', loadTexture: () => Promise.resolve(null) }));
  const gltf = await new Promise((resolve, reject) => loader.parse(ab, '', resolve, reject));
  let mesh = null;
  gltf.scene.traverse((o) => { if (o.isMesh && o.morphTargetInfluences) mesh = o; });
  assert.ok(mesh, `${file}: a mesh with morph targets`);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  mixer.clipAction(gltf.animations[0]).play();
  return { gltf, mesh, mixer };
}

function positions(p, t) {
  p.mixer.setTime(t);
  p.gltf.scene.updateMatrixWorld(true);
  const v = new THREE.Vector3();
  const out = [];
  for (let i = 0; i < p.mesh.geometry.attributes.position.count; ++i) {
    p.mesh.getVertexPosition(i, v);
    out.push(v.clone().applyMatrix4(p.mesh.matrixWorld));
  }
  return out;
}

test('the compact Fox GLB plays in three.js like the per-frame one', { skip: !present && 'run MorphExport.* first' }, async () => {
  const compact = await open(compactFile);
  const frames = await open(framesFile);
  const targets = compact.mesh.morphTargetInfluences.length;
  assert.ok(targets < frames.mesh.morphTargetInfluences.length / 3, `${targets} compact targets`);
  const pos = compact.mesh.geometry.morphAttributes.position;
  assert.equal(pos[1].array.constructor, Int16Array, 'components stay SHORT in three.js');
  const rest = positions(frames, 0);
  const box = new THREE.Box3().setFromPoints(rest);
  const size = Math.max(...box.getSize(new THREE.Vector3()).toArray());
  const duration = compact.gltf.animations[0].duration;
  assert.ok(Math.abs(duration - frames.gltf.animations[0].duration) < 1e-6);
  let worst = 0;
  for (const t of [0, 1 / 60, 0.5, 1.234, duration / 2, duration * 0.9, duration]) {
    const a = positions(compact, t), b = positions(frames, t);
    let d = 0;
    for (let i = 0; i < a.length; ++i) d = Math.max(d, a[i].distanceTo(b[i]));
    worst = Math.max(worst, d);
    assert.ok(d <= 1e-3 * size * 1.001, `t = ${t}: ${d / size} of the size`);
  }
  console.log(`three.js: ${targets} targets, worst ${worst / size} of the size (${size} units) over 7 times`);
});
