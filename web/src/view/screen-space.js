// Mesh vertices on the screen: projection of the displayed (raw) vertices to client pixel
// coordinates, and whether a vertex is visible (not hidden behind another part of the surface:
// a BVH ray cast from the camera, view/picking.js's BVH). Used by the selection brush and by
// the end-to-end tests, which point the real mouse at vertices. vertexVisible / vertexOnScreen
// take an optional target {mesh, picker} (default: the viewer's mesh and picker), e.g. one of
// the two meshes of view/pair-view.js.
import * as THREE from 'three';

const v = new THREE.Vector3();
const ray = new THREE.Ray();
const inverse = new THREE.Matrix4();

// Client coordinates of raw vertices: Float32Array #R·3 of (x, y, ndc z); vertices behind the
// camera or outside the clip volume get z outside -1..1.
export function projectVertices(viewer) {
  const { camera, mesh } = viewer;
  const rect = viewer.renderer.domElement.getBoundingClientRect();
  camera.updateMatrixWorld();
  mesh.updateMatrixWorld();
  const m = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse).multiply(mesh.matrixWorld).elements;
  const p = mesh.geometry.getAttribute('position').array;
  const out = new Float32Array(p.length);
  for (let i = 0; i < p.length; i += 3) {
    const x = p[i], y = p[i + 1], z = p[i + 2];
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    const nx = (m[0] * x + m[4] * y + m[8] * z + m[12]) / w;
    const ny = (m[1] * x + m[5] * y + m[9] * z + m[13]) / w;
    const nz = w > 0 ? (m[2] * x + m[6] * y + m[10] * z + m[14]) / w : 2;
    out[i] = rect.left + ((nx + 1) / 2) * rect.width;
    out[i + 1] = rect.top + ((1 - ny) / 2) * rect.height;
    out[i + 2] = nz;
  }
  return out;
}

// True when the raw vertex is the first surface point the camera sees along its line of sight
// (within a small tolerance of the scene's size).
// `tolerance`: how far (relative to the mesh's bounding radius) the first surface point may lie
// in front of the vertex (landmark numbers use a few percent, so the tip of a paw seen from
// above still counts as seen).
export function vertexVisible(viewer, vertex, { mesh = viewer.mesh, picker = viewer.picker, camera = viewer.camera, tolerance: relative = 1e-3 } = {}) {
  const bvh = picker.ensureBvh();
  if (!bvh) return false;
  const p = mesh.geometry.getAttribute('position').array;
  mesh.updateMatrixWorld();
  inverse.copy(mesh.matrixWorld).invert();
  // In the mesh's own frame: from the camera to the vertex.
  const eye = v.setFromMatrixPosition(camera.matrixWorld).applyMatrix4(inverse);
  ray.origin.copy(eye);
  ray.direction.set(p[3 * vertex] - eye.x, p[3 * vertex + 1] - eye.y, p[3 * vertex + 2] - eye.z);
  const distance = ray.direction.length();
  if (!(distance > 0)) return false;
  ray.direction.divideScalar(distance);
  const hit = bvh.raycastFirst(ray, THREE.DoubleSide);
  const tolerance = relative * (mesh.geometry.boundingSphere?.radius || 1);
  return !hit || hit.distance >= distance - tolerance;
}

// Where a raw vertex is on the screen: {x, y} in client pixels, visible (in the view and not
// hidden by the surface). target: {mesh, picker, camera, rect} (default: the viewer's mesh,
// picker, camera and canvas), e.g. a side of view/pair-view.js in its pane.
export function vertexOnScreen(viewer, vertex, target = {}) {
  const camera = target.camera ?? viewer.camera;
  const mesh = target.mesh ?? viewer.mesh;
  const rect = target.rect ?? viewer.renderer.domElement.getBoundingClientRect();
  camera.updateMatrixWorld();
  const world = new THREE.Vector3().fromBufferAttribute(mesh.geometry.getAttribute('position'), vertex).applyMatrix4(mesh.matrixWorld);
  const ndc = world.clone().project(camera);
  const x = rect.left + ((ndc.x + 1) / 2) * rect.width;
  const y = rect.top + ((1 - ndc.y) / 2) * rect.height;
  const inView = Math.abs(ndc.x) < 1 && Math.abs(ndc.y) < 1 && Math.abs(ndc.z) < 1;
  return { x, y, visible: inView && mesh.visible && vertexVisible(viewer, vertex, { mesh, picker: target.picker ?? viewer.picker, camera, tolerance: target.tolerance }) };
}
