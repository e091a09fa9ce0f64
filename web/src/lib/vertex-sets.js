// Vertex sets on the welded mesh (the one the core edits): membership arrays, the 1-ring
// adjacency computed from the welded triangles, and grow / shrink by one ring. The page only
// has the displayed (raw) triangles and the raw → welded map, so weldedTriangles() rebuilds the
// welded index buffer from them (glTF seams split vertices; welding joins them again).

// Raw triangle indices (#T·3) through toWelded → welded triangle indices (#T·3).
export function weldedTriangles(rawIndices, toWelded) {
  const out = new Uint32Array(rawIndices.length);
  for (let i = 0; i < rawIndices.length; ++i) out[i] = toWelded[rawIndices[i]];
  return out;
}

// 1-ring adjacency of `count` vertices from triangles (#T·3) as CSR: the neighbours of v are
// neighbors[offsets[v] .. offsets[v + 1]), sorted, without duplicates or v itself.
export function vertexAdjacency(triangles, count) {
  const lists = Array.from({ length: count }, () => []);
  for (let f = 0; f < triangles.length; f += 3) {
    for (let k = 0; k < 3; ++k) {
      const a = triangles[f + k];
      const b = triangles[f + ((k + 1) % 3)];
      if (a === b) continue;
      lists[a].push(b);
      lists[b].push(a);
    }
  }
  const offsets = new Uint32Array(count + 1);
  const unique = lists.map((l) => [...new Set(l)].sort((x, y) => x - y));
  for (let v = 0; v < count; ++v) offsets[v + 1] = offsets[v] + unique[v].length;
  const neighbors = new Uint32Array(offsets[count]);
  for (let v = 0; v < count; ++v) neighbors.set(unique[v], offsets[v]);
  return { offsets, neighbors };
}

// Members of a set (Uint8Array, 1 = in) as a sorted index array.
export function members(set) {
  const out = [];
  for (let v = 0; v < set.length; ++v) if (set[v]) out.push(v);
  return out;
}

export function setFromIndices(indices, count) {
  const set = new Uint8Array(count);
  for (const v of indices) {
    if (!Number.isInteger(v) || v < 0 || v >= count) throw new RangeError(`vertex index ${v} is outside 0..${count - 1}`);
    set[v] = 1;
  }
  return set;
}

// The set plus every neighbour of a member (in place; returns the set).
export function grow(set, { offsets, neighbors }) {
  const add = [];
  for (let v = 0; v < set.length; ++v) {
    if (!set[v]) continue;
    for (let j = offsets[v]; j < offsets[v + 1]; ++j) if (!set[neighbors[j]]) add.push(neighbors[j]);
  }
  for (const v of add) set[v] = 1;
  return set;
}

// The set minus every member that has a neighbour outside it (in place; returns the set).
export function shrink(set, { offsets, neighbors }) {
  const drop = [];
  for (let v = 0; v < set.length; ++v) {
    if (!set[v]) continue;
    for (let j = offsets[v]; j < offsets[v + 1]; ++j) {
      if (!set[neighbors[j]]) {
        drop.push(v);
        break;
      }
    }
  }
  for (const v of drop) set[v] = 0;
  return set;
}
