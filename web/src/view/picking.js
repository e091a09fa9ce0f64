// Vertex picking on the displayed mesh. A BVH (three-mesh-bvh, built in "indirect" mode so
// the geometry's index buffer keeps its order) answers a ray cast in O(log n); the picked
// vertex is the corner of the hit triangle nearest to the hit point. The BVH is dropped when
// the target mesh changes and built again on the next pick, so loading a mesh costs nothing
// until the user points at it. No DOM here: view/viewer.js turns pointer positions into rays,
// and node tests (tests/js/picking.test.mjs) run this file as is.
//
// A pick is a plain object (it goes into window.__meshmorph.state):
//   {vertex, welded, point: [x, y, z], face, hit: [x, y, z], distance}
//   vertex   index of the picked vertex in the displayed (raw) layout
//   welded   its index on the welded mesh the core works on (toWelded[vertex]), or null when
//            the mapping is not known
//   point    the vertex's position; hit: where the ray met the surface (both world space)
//   face     index of the hit triangle in the displayed index buffer
//   distance from the ray origin to `hit`
import * as THREE from 'three';
import { MeshBVH } from 'three-mesh-bvh';

// Pointer position (clientX/clientY) → normalised device coordinates over `rect`
// (a DOMRect-like {left, top, width, height}): x, y in -1..1, y up.
export function ndcFromClient(clientX, clientY, rect) {
  return [((clientX - rect.left) / rect.width) * 2 - 1, 1 - ((clientY - rect.top) / rect.height) * 2];
}

// Of the vertex indices `corners`, the one whose position (flat xyz array `positions`) is
// nearest to `point` ([x, y, z]); ties go to the earlier corner.
export function nearestCorner(positions, corners, point) {
  let best = corners[0];
  let bestDistance = Infinity;
  for (const v of corners) {
    const dx = positions[3 * v] - point[0];
    const dy = positions[3 * v + 1] - point[1];
    const dz = positions[3 * v + 2] - point[2];
    const d = dx * dx + dy * dy + dz * dz;
    if (d < bestDistance) {
      bestDistance = d;
      best = v;
    }
  }
  return best;
}

export class VertexPicker {
  constructor() {
    this.mesh = null;
    this.toWelded = null;
    this.bvh = null;
    this.bvhGeometry = null;
    this.buildMs = 0;          // time the last BVH build took
    this.moved = false;        // vertices moved since the BVH was built / refitted
    this.raycaster = new THREE.Raycaster();
    this.inverse = new THREE.Matrix4();
    this.localRay = new THREE.Ray();
    this.ndc = new THREE.Vector2();
  }

  // Picks on `mesh` (a THREE.Mesh with indexed geometry) from now on. toWelded: the raw →
  // welded vertex map (Uint32Array) or null.
  setTarget(mesh, { toWelded = null } = {}) {
    this.mesh = mesh;
    this.toWelded = toWelded;
    this.bvh = null;
    this.bvhGeometry = null;
    this.moved = false;
  }

  // The target's vertices moved, its triangles did not (an edit preview): refit the boxes.
  refit() {
    this.moved = false;
    if (this.bvh && this.bvhGeometry === this.mesh?.geometry) this.bvh.refit();
    else this.bvh = null;
  }

  // Like refit(), at the next pick: a gizmo drag moves the vertices many times a second and
  // nobody picks meanwhile.
  refitLater() {
    this.moved = true;
  }

  // The BVH of the target's current geometry, built on demand.
  ensureBvh() {
    const geometry = this.mesh?.geometry;
    if (!geometry?.getAttribute('position') || !geometry.index) return null;
    if (this.bvh && this.bvhGeometry === geometry) {
      if (this.moved) this.refit();
      return this.bvh;
    }
    const started = performance.now();
    this.bvh = new MeshBVH(geometry, { indirect: true });
    this.bvhGeometry = geometry;
    this.moved = false;
    this.buildMs = performance.now() - started;
    return this.bvh;
  }

  // Pick from normalised device coordinates (x, y in -1..1) through `camera`.
  pickNdc(x, y, camera) {
    this.raycaster.setFromCamera(this.ndc.set(x, y), camera);
    return this.pickRay(this.raycaster.ray);
  }

  // Pick along a world-space THREE.Ray; null when it misses the mesh. Back faces count only
  // when the material draws them.
  pickRay(ray) {
    const bvh = this.ensureBvh();
    if (!bvh) return null;
    const { mesh } = this;
    mesh.updateMatrixWorld();
    this.localRay.copy(ray).applyMatrix4(this.inverse.copy(mesh.matrixWorld).invert());
    // (a mesh drawn with several materials names the side in userData.pickSide).
    const side = mesh.userData.pickSide ?? (Array.isArray(mesh.material) ? mesh.material[0]?.side : mesh.material.side);
    const hit = bvh.raycastFirst(this.localRay, side ?? THREE.FrontSide);
    if (!hit) return null;
    const positions = mesh.geometry.getAttribute('position').array;
    const vertex = nearestCorner(positions, [hit.face.a, hit.face.b, hit.face.c], hit.point.toArray());
    const point = new THREE.Vector3().fromArray(positions, 3 * vertex).applyMatrix4(mesh.matrixWorld);
    const world = hit.point.clone().applyMatrix4(mesh.matrixWorld);
    return {
      vertex,
      welded: this.toWelded ? this.toWelded[vertex] : null,
      point: point.toArray(),
      face: hit.faceIndex,
      hit: world.toArray(),
      distance: world.distanceTo(ray.origin),
    };
  }
}
