// Vertex picking (web/src/view/picking.js) without a browser: the pure helpers, and the BVH
// picker against three.js's brute-force Mesh.raycast on a sphere of 50k+ vertices (same
// triangle, same vertex), the welded index, refit after a move, and that a pick through a
// camera is fast (a BVH query, not a scan of every triangle).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import * as THREE from 'three';
import { VertexPicker, ndcFromClient, nearestCorner } from '../../web/src/view/picking.js';

// A seeded generator, so every run casts the same rays.
function random(seed) {
  let s = seed >>> 0;
  return () => {
    s = (s * 1664525 + 1013904223) >>> 0;
    return s / 2 ** 32;
  };
}

function bigSphere() {
  const geometry = new THREE.SphereGeometry(1, 256, 200); // 257 × 201 = 51 657 vertices
  const mesh = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ side: THREE.FrontSide }));
  mesh.position.set(0.5, -0.25, 2); // a non-identity transform: picks come back in world space
  mesh.updateMatrixWorld();
  return mesh;
}

// Rays from outside the sphere towards random points near its centre.
function rays(mesh, count, seed) {
  const rnd = random(seed);
  const centre = mesh.position;
  const out = [];
  for (let i = 0; i < count; ++i) {
    const dir = new THREE.Vector3(rnd() * 2 - 1, rnd() * 2 - 1, rnd() * 2 - 1).normalize();
    const origin = centre.clone().addScaledVector(dir, 4);
    const target = centre.clone().add(new THREE.Vector3(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).multiplyScalar(0.8));
    out.push(new THREE.Ray(origin, target.sub(origin).normalize()));
  }
  return out;
}

test('nearestCorner and ndcFromClient', () => {
  const positions = new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 5, 5, 5]);
  assert.equal(nearestCorner(positions, [0, 1, 2], [0.9, 0.1, 0]), 1);
  assert.equal(nearestCorner(positions, [0, 1, 2], [0.1, 0.8, 0]), 2);
  assert.equal(nearestCorner(positions, [3, 0], [0.1, 0.1, 0.1]), 0);
  assert.equal(nearestCorner(positions, [1, 2], [0.5, 0.5, 0]), 1, 'ties go to the earlier corner');
  const rect = { left: 100, top: 50, width: 400, height: 200 };
  assert.deepEqual(ndcFromClient(300, 150, rect), [0, 0]);
  assert.deepEqual(ndcFromClient(100, 50, rect), [-1, 1]);
  assert.deepEqual(ndcFromClient(500, 250, rect), [1, -1]);
});

test('BVH picks agree with brute-force raycasting on a 51k-vertex sphere', () => {
  const mesh = bigSphere();
  const positions = mesh.geometry.getAttribute('position').array;
  assert.ok(positions.length / 3 > 50000);
  const indexBefore = mesh.geometry.index.array.slice();
  const picker = new VertexPicker();
  picker.setTarget(mesh);
  const raycaster = new THREE.Raycaster();
  let compared = 0;
  for (const ray of rays(mesh, 40, 7)) {
    const pick = picker.pickRay(ray);
    raycaster.ray.copy(ray);
    const [brute] = raycaster.intersectObject(mesh); // three.js without a BVH tests every triangle
    if (!brute) {
      assert.equal(pick, null);
      continue;
    }
    assert.ok(pick, 'the BVH missed a triangle the brute-force cast hit');
    assert.equal(pick.face, brute.faceIndex);
    assert.ok(Math.abs(pick.distance - brute.distance) < 1e-9 * Math.max(1, brute.distance) + 1e-6);
    const local = mesh.worldToLocal(brute.point.clone()).toArray();
    const expected = nearestCorner(positions, [brute.face.a, brute.face.b, brute.face.c], local);
    assert.equal(pick.vertex, expected);
    const world = new THREE.Vector3().fromArray(positions, 3 * expected).applyMatrix4(mesh.matrixWorld).toArray();
    pick.point.forEach((v, i) => assert.ok(Math.abs(v - world[i]) < 1e-6));
    assert.equal(pick.welded, null, 'no welded index without a map');
    compared += 1;
  }
  assert.ok(compared >= 35, `only ${compared} rays hit`);
  assert.deepEqual(mesh.geometry.index.array, indexBefore, 'building the BVH reordered the index buffer');
  assert.equal(picker.pickRay(new THREE.Ray(new THREE.Vector3(10, 10, 10), new THREE.Vector3(1, 0, 0))), null);
});

test('picks are BVH queries: fast on 50k+ vertices, welded index from the map, refit after a move', () => {
  const mesh = bigSphere();
  const count = mesh.geometry.getAttribute('position').count;
  const toWelded = new Uint32Array(count).map((_, i) => count - 1 - i);
  const picker = new VertexPicker();
  picker.setTarget(mesh, { toWelded });
  const all = rays(mesh, 2000, 11);
  picker.pickRay(all[0]); // builds the BVH
  assert.ok(picker.buildMs < 5000, `BVH build took ${picker.buildMs} ms`);
  const started = performance.now();
  let hits = 0;
  for (const ray of all) {
    const pick = picker.pickRay(ray);
    if (pick) {
      hits += 1;
      assert.equal(pick.welded, toWelded[pick.vertex]);
    }
  }
  const perPick = (performance.now() - started) / all.length;
  assert.ok(hits > all.length * 0.9);
  // A brute-force pick tests ~102k triangles (several ms); a BVH query visits a few nodes.
  assert.ok(perPick < 1, `${perPick.toFixed(3)} ms per pick`);

  // Move every vertex outward by 10 %: after refit the picks see the new surface.
  const position = mesh.geometry.getAttribute('position');
  for (let i = 0; i < position.array.length; ++i) position.array[i] *= 1.1;
  position.needsUpdate = true;
  picker.refit();
  const ray = new THREE.Ray(mesh.position.clone().add(new THREE.Vector3(0, 0, 5)), new THREE.Vector3(0, 0, -1));
  const pick = picker.pickRay(ray);
  assert.ok(Math.abs(pick.distance - (5 - 1.1)) < 1e-3, `distance ${pick.distance}`);
  // refitLater (edit previews): the next pick refits.
  for (let i = 0; i < position.array.length; ++i) position.array[i] /= 1.1;
  picker.refitLater();
  assert.ok(Math.abs(picker.pickRay(ray).distance - 4) < 1e-3, 'the pick after refitLater missed the moved surface');

  // A new target drops the BVH.
  const small = new THREE.Mesh(new THREE.BoxGeometry(1, 1, 1), new THREE.MeshBasicMaterial());
  picker.setTarget(small);
  const boxPick = picker.pickRay(new THREE.Ray(new THREE.Vector3(0.2, 0.3, 5), new THREE.Vector3(0, 0, -1)));
  assert.ok(Math.abs(boxPick.distance - 4.5) < 1e-9);
  assert.deepEqual(boxPick.point, [0.5, 0.5, 0.5]);
});

test('a pick through a camera hits the point under the NDC position', () => {
  const mesh = bigSphere();
  const camera = new THREE.PerspectiveCamera(40, 1.5, 0.1, 100);
  camera.position.set(0.5, -0.25, 6);
  camera.lookAt(mesh.position);
  camera.updateMatrixWorld();
  const picker = new VertexPicker();
  picker.setTarget(mesh);
  const centre = picker.pickNdc(0, 0, camera);
  assert.ok(Math.abs(centre.distance - 3) < 1e-3, `distance ${centre.distance}`);
  assert.ok(Math.abs(centre.point[2] - 3) < 0.02, `picked vertex ${centre.point}`);
  assert.equal(picker.pickNdc(0.95, 0.95, camera), null, 'the corner of the view is background');
});
