// Small geometry of the Merge job on the main thread (no three.js, node-testable): the cut
// previews (which vertices a plane or a geodesic disk removes), a boundary loop's centre,
// normal and length, and the similarity that puts the source's loop onto the target's (the
// starting placement of the configuration-dependent mode). Positions are flat #V·3 arrays;
// loops are vertex index lists in face orientation (the boundaryLoops binding).

// Per vertex: 1 when the plane cut removes it (the side the normal does not point to), else 0.
export function planeRemoves(positions, point, normal) {
  const n = positions.length / 3;
  const out = new Uint8Array(n);
  for (let v = 0; v < n; ++v) {
    const d = (positions[3 * v] - point[0]) * normal[0] + (positions[3 * v + 1] - point[1]) * normal[1] + (positions[3 * v + 2] - point[2]) * normal[2];
    out[v] = d < 0 ? 1 : 0;
  }
  return out;
}

// Edge-length (Dijkstra) distances from `source` on a mesh: the distance the core's disk cut
// measures. adjacency: {offsets, neighbors} (lib/vertex-sets.js vertexAdjacency). Stops at
// `limit` (vertices further away get Infinity).
export function edgeDistances(positions, { offsets, neighbors }, source, limit = Infinity) {
  const n = offsets.length - 1;
  const dist = new Float64Array(n).fill(Infinity);
  const heap = [];  // [distance, vertex] binary min-heap
  const push = (d, v) => {
    heap.push([d, v]);
    for (let i = heap.length - 1; i > 0;) {
      const parent = (i - 1) >> 1;
      if (heap[parent][0] <= heap[i][0]) break;
      [heap[parent], heap[i]] = [heap[i], heap[parent]];
      i = parent;
    }
  };
  const pop = () => {
    const top = heap[0];
    const last = heap.pop();
    if (heap.length) {
      heap[0] = last;
      for (let i = 0; ;) {
        const l = 2 * i + 1;
        const r = l + 1;
        let m = i;
        if (l < heap.length && heap[l][0] < heap[m][0]) m = l;
        if (r < heap.length && heap[r][0] < heap[m][0]) m = r;
        if (m === i) break;
        [heap[m], heap[i]] = [heap[i], heap[m]];
        i = m;
      }
    }
    return top;
  };
  dist[source] = 0;
  push(0, source);
  while (heap.length) {
    const [d, v] = pop();
    if (d > dist[v] || d > limit) continue;
    for (let j = offsets[v]; j < offsets[v + 1]; ++j) {
      const w = neighbors[j];
      const e = Math.hypot(positions[3 * v] - positions[3 * w], positions[3 * v + 1] - positions[3 * w + 1], positions[3 * v + 2] - positions[3 * w + 2]);
      if (d + e < dist[w]) {
        dist[w] = d + e;
        push(d + e, w);
      }
    }
  }
  return dist;
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);
const unit = (a) => scale(a, 1 / (norm(a) || 1));
const point = (positions, v) => [positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]];

// A loop's centre (mean of its vertices), length, and the direction out of the mesh through
// its opening (a loop in face orientation runs clockwise seen from outside the opening, so the
// outward direction is minus its area vector).
export function loopFrame(positions, loop) {
  let centre = [0, 0, 0];
  for (const v of loop) centre = add(centre, point(positions, v));
  centre = scale(centre, 1 / loop.length);
  let area = [0, 0, 0];
  let length = 0;
  loop.forEach((v, i) => {
    const a = sub(point(positions, v), centre);
    const b = sub(point(positions, loop[(i + 1) % loop.length]), centre);
    area = add(area, scale(cross(a, b), 0.5));
    length += norm(sub(b, a));
  });
  return { centre, length, outward: unit(scale(area, -1)), area: norm(area) };
}

// A right-handed orthonormal frame [e1, e2, e3] with e3 = axis and e1 along `toward`
// (projected; any perpendicular when it is parallel to the axis).
function frameAbout(axis, toward) {
  const e3 = unit(axis);
  let e1 = sub(toward, scale(e3, dot(toward, e3)));
  if (norm(e1) < 1e-9 * (norm(toward) || 1)) e1 = Math.abs(e3[0]) < 0.9 ? cross(e3, [1, 0, 0]) : cross(e3, [0, 1, 0]);
  e1 = unit(e1);
  return [e1, cross(e3, e1), e3];
}

// The similarity (column-major 4x4) that puts the source's loop onto the target's: centre on
// centre, the source continuing out of the target's opening (its own opening facing into the
// target), scaled so the loop lengths agree, turned so the first key pair's vertices line up
// (keys: [targetVertex, sourceVertex] or null).
export function placeOnLoop(target, targetLoop, source, sourceLoop, keys = null) {
  const t = loopFrame(target, targetLoop);
  const s = loopFrame(source, sourceLoop);
  const towardT = keys ? sub(point(target, keys[0]), t.centre) : [0, 0, 0];
  const towardS = keys ? sub(point(source, keys[1]), s.centre) : [0, 0, 0];
  const ft = frameAbout(t.outward, keys ? towardT : [0, 0, 1]);
  // Without keys: the minimal rotation taking -outward_s to outward_t (frames built from a
  // shared reference direction would add an arbitrary twist).
  const fs = keys ? frameAbout(scale(s.outward, -1), towardS) : null;
  let R;
  if (fs) {
    // R = Ft Fsᵀ (columns e1, e2, e3).
    R = [0, 1, 2].map((i) => [0, 1, 2].map((j) => ft[0][i] * fs[0][j] + ft[1][i] * fs[1][j] + ft[2][i] * fs[2][j]));
  } else {
    R = rotationBetween(scale(s.outward, -1), t.outward);
  }
  const k = s.length > 0 ? t.length / s.length : 1;
  const rc = [0, 1, 2].map((i) => R[i][0] * s.centre[0] + R[i][1] * s.centre[1] + R[i][2] * s.centre[2]);
  const tr = sub(t.centre, scale(rc, k));
  return [
    k * R[0][0], k * R[1][0], k * R[2][0], 0,
    k * R[0][1], k * R[1][1], k * R[2][1], 0,
    k * R[0][2], k * R[1][2], k * R[2][2], 0,
    tr[0], tr[1], tr[2], 1,
  ];
}

// The rotation (row-major 3x3) taking unit a to unit b along the shortest arc.
function rotationBetween(a, b) {
  a = unit(a);
  b = unit(b);
  const v = cross(a, b);
  const c = dot(a, b);
  if (c < -1 + 1e-12) {
    const [e1] = frameAbout(a, [1, 0, 0]);
    return [0, 1, 2].map((i) => [0, 1, 2].map((j) => 2 * e1[i] * e1[j] - (i === j ? 1 : 0)));
  }
  const K = [[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]];
  const K2 = [0, 1, 2].map((i) => [0, 1, 2].map((j) => K[i][0] * K[0][j] + K[i][1] * K[1][j] + K[i][2] * K[2][j]));
  return [0, 1, 2].map((i) => [0, 1, 2].map((j) => (i === j ? 1 : 0) + K[i][j] + K2[i][j] / (1 + c)));
}

// How to show a seam whose target opening faces `outward`: {right, up} (orthonormal, in the
// meshes' coordinates) for a display turned so that the seam axis runs across the screen —
// target on the left, source on the right — and "up" is the mesh's y or z axis, whichever is
// further from the axis (so a z-up quadruped's neck is seen from the side, not from above).
// null when the opening faces up or down (|outward·y| > 0.8): the page's usual y-up view
// already shows that seam from the side.
export function seamView(outward) {
  const o = unit(outward);
  if (Math.abs(o[1]) > 0.8) return null;
  const right = o[0] < -1e-9 ? scale(o, -1) : o;
  const candidates = [[0, 1, 0], [0, 0, 1]];
  const axis = Math.abs(dot(candidates[0], o)) <= Math.abs(dot(candidates[1], o)) + 1e-9 ? candidates[0] : candidates[1];
  let up = sub(axis, scale(right, dot(axis, right)));
  if (norm(up) < 1e-6) return null;
  up = unit(up);
  return { right, up };
}

// Bounding-box diagonal of flat positions.
export function bboxDiagonal(positions) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < positions.length; i += 3) {
    for (let k = 0; k < 3; ++k) {
      lo[k] = Math.min(lo[k], positions[i + k]);
      hi[k] = Math.max(hi[k], positions[i + k]);
    }
  }
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

// A random similarity (column-major 4x4): rotation about a random axis, scale in [0.3, 3],
// translation up to `reach` — the paper's Fig. 1 check that the independent mode ignores it.
export function randomSimilarity(reach = 1, random = Math.random) {
  const axis = unit([random() - 0.5, random() - 0.5, random() - 0.5]);
  const angle = (random() * 2 - 1) * Math.PI;
  const k = 0.3 * 10 ** random();
  const c = Math.cos(angle);
  const s = Math.sin(angle);
  const [x, y, z] = axis;
  const R = [
    [c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
    [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
    [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)],
  ];
  const t = [0, 1, 2].map(() => (random() * 2 - 1) * reach);
  return [
    k * R[0][0], k * R[1][0], k * R[2][0], 0,
    k * R[0][1], k * R[1][1], k * R[2][1], 0,
    k * R[0][2], k * R[1][2], k * R[2][2], 0,
    t[0], t[1], t[2], 1,
  ];
}
