// three.js ⇄ flat typed arrays: the only place that knows how geometry is laid out on either
// side of the worker boundary (positions #V·3 Float32, indices #T·3 Uint32, per-vertex
// attributes #V·itemSize).
import * as THREE from 'three';

// Flat copies of a geometry's positions and triangle indices, safe to transfer to the worker
// (transferring detaches the buffers, so never hand over the geometry's own arrays).
export function toArrays(geometry) {
  const positions = new Float32Array(geometry.getAttribute('position').array);
  let indices;
  if (geometry.index) {
    indices = new Uint32Array(geometry.index.array);
  } else {
    const n = geometry.getAttribute('position').count;
    indices = new Uint32Array(n);
    for (let i = 0; i < n; ++i) indices[i] = i;
  }
  return { positions, indices };
}

// Swaps the given arrays into `geometry`. Keys: positions, normals, colors (itemSize 3),
// indices. An attribute of the same length is updated in place (no GPU re-allocation while
// scrubbing the eigenfunction slider); otherwise it is replaced. `colors: null` removes colours.
export function applyArrays(geometry, { positions, normals, colors, indices } = {}) {
  setAttribute(geometry, 'position', positions);
  setAttribute(geometry, 'normal', normals);
  if (colors === null) geometry.deleteAttribute('color');
  else setAttribute(geometry, 'color', colors);
  if (indices) {
    if (geometry.index && geometry.index.array.length === indices.length) {
      geometry.index.array.set(indices);
      geometry.index.needsUpdate = true;
    } else {
      geometry.setIndex(new THREE.BufferAttribute(indices, 1));
    }
  }
  if (positions) {
    geometry.computeBoundingBox();
    geometry.computeBoundingSphere();
  }
  return geometry;
}

function setAttribute(geometry, name, array) {
  if (!array) return;
  const current = geometry.getAttribute(name);
  if (current && current.array.length === array.length) {
    current.array.set(array);
    current.needsUpdate = true;
  } else {
    geometry.setAttribute(name, new THREE.BufferAttribute(array, 3));
  }
}

// Spreads per-welded-vertex values (#W·itemSize) to the raw layout (#R·itemSize) through the
// Asset's vertex map: glTF seams split vertices, results are computed on the welded mesh.
export function unweldValues(values, toWelded, itemSize, out = new Float32Array(toWelded.length * itemSize)) {
  for (let r = 0; r < toWelded.length; ++r) {
    const w = toWelded[r] * itemSize;
    for (let c = 0; c < itemSize; ++c) out[r * itemSize + c] = values[w + c];
  }
  return out;
}

// Area-weighted vertex normals (unit length; #V·3 Float32Array) of a triangle mesh: positions
// #V·3, indices #F·3. The worker computes them for previews (ops/edit.js), so the main thread
// only copies arrays while a gizmo is dragged.
export function vertexNormals(positions, indices, count = positions.length / 3) {
  const n = new Float32Array(count * 3);
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t];
    const b = 3 * indices[t + 1];
    const c = 3 * indices[t + 2];
    const ux = positions[b] - positions[a];
    const uy = positions[b + 1] - positions[a + 1];
    const uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a];
    const vy = positions[c + 1] - positions[a + 1];
    const vz = positions[c + 2] - positions[a + 2];
    const x = uy * vz - uz * vy;
    const y = uz * vx - ux * vz;
    const z = ux * vy - uy * vx;
    for (const i of [a, b, c]) {
      n[i] += x;
      n[i + 1] += y;
      n[i + 2] += z;
    }
  }
  for (let i = 0; i < n.length; i += 3) {
    const length = Math.sqrt(n[i] * n[i] + n[i + 1] * n[i + 1] + n[i + 2] * n[i + 2]) || 1;
    n[i] /= length;
    n[i + 1] /= length;
    n[i + 2] /= length;
  }
  return n;
}
