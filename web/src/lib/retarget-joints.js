// Target joints of the Retarget job on the page: the joints file the CLI reads
// (`meshmorph retarget --target-joints J.json`: {"joint name": [x, y, z]} in the target's
// coordinates), the bones drawn between joints, and joints that follow the retargeted surface
// during playback (for the overlay and the bone-length plot).
//
// The core's own per-frame joints (f_t(J_t), RetargetFrame::joints) are not returned by the wasm
// binding, so the page follows each joint with its nearest surface vertices: a joint moves by
// the mean displacement of its `k` nearest rest vertices. It is an estimate of the skeleton's
// motion, labelled so in the page; bone lengths measured on it show where the surface stretched.
import { MeshMorphError } from './errors.js';

// A joints file (parsed JSON) → [{name, position: [x, y, z]}] in the file's order.
// min: the fewest joints the file may hold (a joints file 2; pins, the CLI's --markers file, 1).
export function readJointsFile(json, fileName = 'joints file', { min = 2 } = {}) {
  if (!json || typeof json !== 'object' || Array.isArray(json)) {
    throw new MeshMorphError('ParseError', `${fileName}: expected an object {"joint name": [x, y, z], ...}`);
  }
  const out = [];
  for (const [name, p] of Object.entries(json)) {
    if (!Array.isArray(p) || p.length !== 3 || !p.every((v) => typeof v === 'number' && Number.isFinite(v))) {
      throw new MeshMorphError('ParseError', `${fileName}: joint "${name}" must be [x, y, z] (three finite numbers)`);
    }
    out.push({ name, position: [...p] });
  }
  if (out.length < min) throw new MeshMorphError('ParseError', `${fileName}: needs at least ${min} joint${min === 1 ? '' : 's'} (found ${out.length})`);
  return out;
}

// The same from the file's text (a joints file or pins): malformed JSON is a ParseError naming the file.
export function parseJointsText(text, fileName = 'joints file', options = {}) {
  let parsed;
  try {
    parsed = JSON.parse(text);
  } catch (e) {
    throw new MeshMorphError('ParseError', `${fileName}: ${e.message}`);
  }
  return readJointsFile(parsed, fileName, options);
}

// The joints as the CLI's file (insertion order kept).
export function jointsFile(joints) {
  return Object.fromEntries(joints.map((j) => [j.name, j.position.map((v) => Number(v.toPrecision(9)))]));
}

// Bones between the given joints: [child, parent] index pairs, the parent being the nearest
// ancestor (parentOf(name) → parent name or null, from a skeleton) that is also in the list.
export function bonesOf(names, parentOf) {
  const index = new Map(names.map((n, i) => [n, i]));
  const bones = [];
  names.forEach((name, i) => {
    const seen = new Set([name]);
    let p = parentOf(name);
    while (p != null && !index.has(p) && !seen.has(p)) {
      seen.add(p);
      p = parentOf(p);
    }
    if (p != null && index.has(p)) bones.push([i, index.get(p)]);
  });
  return bones;
}

// Follows joints with their k nearest vertices of the rest surface (see above).
export class JointFollower {
  // rest: Float32Array #V·3; joints: [[x, y, z]].
  constructor(rest, joints, k = 16) {
    this.rest = rest;
    this.joints = joints.map((p) => [...p]);
    this.k = Math.min(k, rest.length / 3);
    this.near = this.joints.map((p) => nearestVertices(rest, p, this.k));
  }

  // Joint positions for a frame's surface (#V·3) → Float32Array #J·3.
  at(positions, out = new Float32Array(this.joints.length * 3)) {
    const { rest } = this;
    this.joints.forEach((p, j) => {
      let dx = 0;
      let dy = 0;
      let dz = 0;
      for (const v of this.near[j]) {
        dx += positions[3 * v] - rest[3 * v];
        dy += positions[3 * v + 1] - rest[3 * v + 1];
        dz += positions[3 * v + 2] - rest[3 * v + 2];
      }
      const n = this.near[j].length;
      out[3 * j] = p[0] + dx / n;
      out[3 * j + 1] = p[1] + dy / n;
      out[3 * j + 2] = p[2] + dz / n;
    });
    return out;
  }
}

// The k nearest vertices (ties: lower index first), by insertion into a sorted list of k: O(#V·k).
function nearestVertices(rest, p, k) {
  const n = rest.length / 3;
  const best = [];   // vertex indices, nearest first
  const dist = [];   // their squared distances
  for (let v = 0; v < n; ++v) {
    const d = (rest[3 * v] - p[0]) ** 2 + (rest[3 * v + 1] - p[1]) ** 2 + (rest[3 * v + 2] - p[2]) ** 2;
    if (best.length === k && d >= dist[k - 1]) continue;
    let i = best.length === k ? k - 1 : best.length;
    while (i > 0 && dist[i - 1] > d) {
      if (i < k) { best[i] = best[i - 1]; dist[i] = dist[i - 1]; }
      i -= 1;
    }
    best[i] = v;
    dist[i] = d;
  }
  return best;
}

const lengthOf = (p, a, b) => Math.hypot(p[3 * a] - p[3 * b], p[3 * a + 1] - p[3 * b + 1], p[3 * a + 2] - p[3 * b + 2]);

// Bone lengths (joints #J·3 flat, bones [[child, parent]]) → Float64Array.
export function boneLengths(joints, bones) {
  return Float64Array.from(bones, ([a, b]) => lengthOf(joints, a, b));
}

// Relative bone-length change of a pose against rest lengths: {mean, max} of |ℓ/ℓ₀ − 1| over
// bones with ℓ₀ > 0.
export function boneLengthChange(joints, bones, restLengths) {
  let sum = 0;
  let max = 0;
  let n = 0;
  bones.forEach(([a, b], i) => {
    if (!(restLengths[i] > 0)) return;
    const e = Math.abs(lengthOf(joints, a, b) / restLengths[i] - 1);
    sum += e;
    max = Math.max(max, e);
    n += 1;
  });
  return { mean: n ? sum / n : 0, max };
}
