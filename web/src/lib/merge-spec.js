// The Merge job's key pairs and its spec file: the JSON `meshmorph merge --spec` reads
// (app/merge_job.h), restricted to what the page edits — one boundary pair, its key vertices
// (welded indices of the target and of the source), the source's fixed vertices
// (configuration-dependent mode) and the options. Also the checks the page makes before it
// asks the core (key order along the loops, the same rule as core/merge/mesh_merge.cpp), so a
// person sees a problem while picking, not only when the merge fails.
import { MeshMorphError } from './errors.js';

export const minKeys = 2; // the core needs two key pairs per boundary pair

// Key vertex pairs [[target, source], ...] picked by clicks: the first click of a pair (on either
// mesh) waits; a click on the other mesh completes it; a second click on the same mesh moves the
// waiting half.
export class KeyPairs {
  constructor() {
    this.pairs = [];
    this.pending = null; // {side: 'target' | 'source', vertex}
  }

  click(side, vertex) {
    if (!this.pending || this.pending.side === side) {
      this.pending = { side, vertex };
      return 'pending';
    }
    this.pairs.push(side === 'source' ? [this.pending.vertex, vertex] : [vertex, this.pending.vertex]);
    this.pending = null;
    return 'paired';
  }

  remove(index) {
    this.pairs.splice(index, 1);
  }

  // Moves pair `index` by `delta` places (-1 up, +1 down); returns its new index.
  move(index, delta) {
    const to = index + delta;
    if (index < 0 || index >= this.pairs.length || to < 0 || to >= this.pairs.length) return index;
    const [pair] = this.pairs.splice(index, 1);
    this.pairs.splice(to, 0, pair);
    return to;
  }

  clear() {
    this.pairs = [];
    this.pending = null;
  }
}

// The spec document the page saves and the merge op reads. pairs: [[t, s], ...]; fixed: source
// vertices (dependent mode only); options: the changed options (mode included when dependent);
// comment: free text (how the inputs were made, so the CLI gets the same meshes).
export function buildMergeSpec({ pairs, fixed = [], options = {}, comment = '' }) {
  const spec = {};
  if (comment) spec.comment = comment;
  spec.pairs = [{ target_keys: pairs.map((p) => p[0]), source_keys: pairs.map((p) => p[1]) }];
  if (fixed.length) spec.fixed = [...fixed];
  if (Object.keys(options).length) spec.options = { ...options };
  return spec;
}

const specKeys = ['pairs', 'fixed', 'options', 'comment'];
const pairKeys = ['target_keys', 'source_keys', 'target_loop', 'source_loop'];

function indexArray(value, where, count) {
  if (!Array.isArray(value) || !value.every(Number.isInteger)) {
    throw new MeshMorphError('ParseError', `merge spec: ${where} must be an array of vertex indices`);
  }
  for (const v of value) {
    if (v < 0 || (count !== undefined && v >= count)) {
      throw new MeshMorphError('InvalidArgument', `merge spec: ${where} has vertex ${v}, but the mesh has ${count} vertices (0…${count - 1}); is it the spec of other meshes?`);
    }
  }
  return value;
}

// A parsed spec document → {pairs: [[t, s], ...], targetLoop, sourceLoop, fixed, options,
// comment}; checked against the meshes' vertex counts when given. Unknown keys are errors, as
// in the CLI. The page handles one boundary pair (several: use the CLI).
export function readMergeSpec(json, { targetVertices, sourceVertices } = {}) {
  if (!json || typeof json !== 'object' || Array.isArray(json)) throw new MeshMorphError('ParseError', 'a merge spec is a JSON object {"pairs": [...], ...}');
  for (const key of Object.keys(json)) {
    if (!specKeys.includes(key)) throw new MeshMorphError('ParseError', `merge spec: unknown key "${key}" (allowed: ${specKeys.join(', ')})`);
  }
  if (!Array.isArray(json.pairs) || json.pairs.length === 0) throw new MeshMorphError('ParseError', 'merge spec: "pairs" must be a non-empty array of boundary pairs');
  if (json.pairs.length > 1) {
    throw new MeshMorphError('Unsupported', `this spec merges ${json.pairs.length} boundary pairs; the page merges one — run it with \`meshmorph merge --spec\``);
  }
  const pair = json.pairs[0];
  if (!pair || typeof pair !== 'object' || Array.isArray(pair)) throw new MeshMorphError('ParseError', 'merge spec: pairs[0] must be an object');
  for (const key of Object.keys(pair)) {
    if (!pairKeys.includes(key)) throw new MeshMorphError('ParseError', `merge spec: unknown key "${key}" in pairs[0] (allowed: ${pairKeys.join(', ')})`);
  }
  const t = indexArray(pair.target_keys, 'pairs[0].target_keys', targetVertices);
  const s = indexArray(pair.source_keys, 'pairs[0].source_keys', sourceVertices);
  if (t.length !== s.length) throw new MeshMorphError('ParseError', `merge spec: ${t.length} target keys but ${s.length} source keys (they are pairs)`);
  for (const name of ['target_loop', 'source_loop']) {
    if (pair[name] !== undefined && !(Number.isInteger(pair[name]) && pair[name] >= 0)) {
      throw new MeshMorphError('ParseError', `merge spec: pairs[0].${name} must be a loop index ≥ 0`);
    }
  }
  const fixed = json.fixed === undefined ? [] : indexArray(json.fixed, 'fixed', sourceVertices);
  const options = json.options ?? {};
  if (typeof options !== 'object' || Array.isArray(options)) throw new MeshMorphError('ParseError', 'merge spec: "options" must be an object');
  return {
    pairs: t.map((v, i) => [v, s[i]]),
    targetLoop: pair.target_loop ?? -1,
    sourceLoop: pair.source_loop ?? -1,
    fixed: [...fixed],
    options: { ...options },
    comment: typeof json.comment === 'string' ? json.comment : '',
  };
}

// Loop lookup: per vertex of a mesh with `count` vertices, the index of its (first) boundary
// loop, or -1. loops: [[v, ...], ...] as the boundaryLoops binding gives them.
export function loopOfVertex(loops, count) {
  const out = new Int32Array(count).fill(-1);
  loops.forEach((loop, l) => {
    for (const v of loop) if (out[v] < 0) out[v] = l;
  });
  return out;
}

// What is wrong with the key pairs for a merge, as a sentence, or null. targetLoop / sourceLoop:
// the loops' vertex lists (face orientation, as boundaryLoops gives them). Mirrors the core's
// order_keys: going along the target loop, the source keys must come in the same order along
// the source loop traversed backwards (the merged faces keep one orientation).
export function keyPairsProblem(pairs, targetLoop, sourceLoop) {
  if (!targetLoop || !sourceLoop) return 'choose a boundary loop on each mesh (click near it)';
  if (pairs.length < minKeys) return `at least ${minKeys} key pairs are needed (${pairs.length} so far)`;
  const tpos = pairs.map(([t]) => targetLoop.indexOf(t));
  const reversed = [...sourceLoop].reverse();
  const spos = pairs.map(([, s]) => reversed.indexOf(s));
  const missingT = tpos.findIndex((p) => p < 0);
  if (missingT >= 0) return `key pair ${missingT + 1}: target vertex ${pairs[missingT][0]} is not on the chosen target loop`;
  const missingS = spos.findIndex((p) => p < 0);
  if (missingS >= 0) return `key pair ${missingS + 1}: source vertex ${pairs[missingS][1]} is not on the chosen source loop`;
  for (const [which, pos] of [['target', tpos], ['source', spos]]) {
    const seen = new Map();
    for (let i = 0; i < pos.length; ++i) {
      if (seen.has(pos[i])) return `key pairs ${seen.get(pos[i]) + 1} and ${i + 1} use the same ${which} vertex`;
      seen.set(pos[i], i);
    }
  }
  const order = pairs.map((_, i) => i).sort((a, b) => tpos[a] - tpos[b]);
  const ms = reversed.length;
  const s0 = spos[order[0]];
  let last = -1;
  let previous = order[0];
  for (const i of order) {
    const rel = (spos[i] - s0 + ms) % ms;
    if (rel <= last) {
      const [a, b] = [previous, i].sort((x, y) => x - y);
      return `key pairs ${a + 1} and ${b + 1} are out of order: going round the target loop, the source keys must come the same way round theirs (swap or delete one)`;
    }
    last = rel;
    previous = i;
  }
  return null;
}
