// Landmark suggestions for the Transfer job: the extremities of a surface (tips of limbs, the
// head, the tail, ears) found with geodesic distances along edges, and a matching between the
// extremities of two meshes. Plain JS on flat arrays (welded positions #V·3, triangles #F·3),
// run by the worker op suggestLandmarks (worker/ops/landmarks.js) and by the node tests.
//
// Extremities: on the largest connected part, two farthest-point sweeps give the ends a, b of a
// long geodesic; the centre c is the vertex with the smallest max(d(a, ·), d(b, ·)). An
// extremity is a local maximum of d(c, ·) (over its 1-ring) at least `minRelative` of the
// largest distance from c, taken farthest first, at least `separation` (relative) from the
// extremities taken before it (a bounded Dijkstra marks their neighbourhoods).
// Matching: an extremity is described by its relative distance from the centre and its
// direction from the centre; pairs are taken greedily by the smallest difference (relative
// distance + half the direction difference), up to `maxCost`. Mirror-symmetric parts (left /
// right legs) are told apart only by direction, so meshes in the same orientation match best;
// the page shows the pairs as suggestions the person accepts or rejects.

// Edges as compressed rows: neighbours of v at [offsets[v], offsets[v + 1]) with their lengths.
export function edgeGraph(positions, triangles, count = positions.length / 3) {
  const degree = new Uint32Array(count + 1);
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; ++k) {
      degree[triangles[t + k]] += 1;
      degree[triangles[t + ((k + 1) % 3)]] += 1;
    }
  }
  const offsets = new Uint32Array(count + 1);
  for (let v = 0; v < count; ++v) offsets[v + 1] = offsets[v] + degree[v];
  const fill = offsets.slice(0, count);
  const neighbours = new Uint32Array(offsets[count]);
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; ++k) {
      const a = triangles[t + k];
      const b = triangles[t + ((k + 1) % 3)];
      neighbours[fill[a]++] = b;
      neighbours[fill[b]++] = a;
    }
  }
  // Interior edges appear twice per vertex (once per triangle): harmless for Dijkstra.
  const lengths = new Float64Array(neighbours.length);
  for (let v = 0; v < count; ++v) {
    for (let e = offsets[v]; e < offsets[v + 1]; ++e) {
      const u = neighbours[e];
      const dx = positions[3 * u] - positions[3 * v];
      const dy = positions[3 * u + 1] - positions[3 * v + 1];
      const dz = positions[3 * u + 2] - positions[3 * v + 2];
      lengths[e] = Math.sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  return { count, offsets, neighbours, lengths };
}

// Edge-length distances from `sources` (vertex indices); vertices farther than maxDistance (or
// unreachable) stay Infinity. `into`: an array to lower in place (distance to a set).
export function dijkstra(graph, sources, { maxDistance = Infinity, into = null } = {}) {
  const { count, offsets, neighbours, lengths } = graph;
  const dist = new Float64Array(count).fill(Infinity);
  // Binary heap of (distance, vertex) with lazy deletion.
  let heapD = new Float64Array(64);
  let heapV = new Uint32Array(64);
  let size = 0;
  const push = (d, v) => {
    if (size === heapD.length) {
      const d2 = new Float64Array(size * 2); d2.set(heapD); heapD = d2;
      const v2 = new Uint32Array(size * 2); v2.set(heapV); heapV = v2;
    }
    let i = size++;
    while (i > 0) {
      const parent = (i - 1) >> 1;
      if (heapD[parent] <= d) break;
      heapD[i] = heapD[parent];
      heapV[i] = heapV[parent];
      i = parent;
    }
    heapD[i] = d;
    heapV[i] = v;
  };
  const pop = () => {
    const d = heapD[--size];
    const v = heapV[size];
    let i = 0;
    for (;;) {
      let child = 2 * i + 1;
      if (child >= size) break;
      if (child + 1 < size && heapD[child + 1] < heapD[child]) child += 1;
      if (heapD[child] >= d) break;
      heapD[i] = heapD[child];
      heapV[i] = heapV[child];
      i = child;
    }
    heapD[i] = d;
    heapV[i] = v;
  };
  for (const s of sources) {
    dist[s] = 0;
    push(0, s);
  }
  while (size > 0) {
    const d = heapD[0];
    const v = heapV[0];
    pop();
    if (d > dist[v]) continue;
    for (let e = offsets[v]; e < offsets[v + 1]; ++e) {
      const u = neighbours[e];
      const nd = d + lengths[e];
      if (nd < dist[u] && nd <= maxDistance) {
        dist[u] = nd;
        push(nd, u);
      }
    }
  }
  if (into) for (let v = 0; v < count; ++v) if (dist[v] < into[v]) into[v] = dist[v];
  return dist;
}

function argmax(values) {
  let best = -1;
  for (let v = 0; v < values.length; ++v) if (Number.isFinite(values[v]) && (best < 0 || values[v] > values[best])) best = v;
  return best;
}

// A vertex of the largest connected part (by vertex count).
function largestPartVertex(graph) {
  const part = new Int32Array(graph.count).fill(-1);
  let best = { size: 0, vertex: 0 };
  const stack = [];
  for (let s = 0; s < graph.count; ++s) {
    if (part[s] >= 0 || graph.offsets[s] === graph.offsets[s + 1]) continue;
    let size = 0;
    part[s] = s;
    stack.push(s);
    while (stack.length) {
      const v = stack.pop();
      size += 1;
      for (let e = graph.offsets[v]; e < graph.offsets[v + 1]; ++e) {
        const u = graph.neighbours[e];
        if (part[u] < 0) { part[u] = s; stack.push(u); }
      }
    }
    if (size > best.size) best = { size, vertex: s };
  }
  return best.vertex;
}

// → {centre, radius (largest distance from the centre), extremities: [{vertex, relative,
//    direction: [x, y, z] unit}], between: geodesic distances between the extremities / radius
//    (row-major n × n)}
export function findExtremities(positions, triangles, { count = 8, minRelative = 0.35, separation = 0.25, bulkRadius = 0.2 } = {}) {
  const graph = edgeGraph(positions, triangles);
  const start = largestPartVertex(graph);
  const a = argmax(dijkstra(graph, [start]));
  const da = dijkstra(graph, [a]);
  const b = argmax(da);
  const db = dijkstra(graph, [b]);
  let centre = a;
  for (let v = 0; v < graph.count; ++v) {
    if (Number.isFinite(da[v]) && Math.max(da[v], db[v]) < Math.max(da[centre], db[centre])) centre = v;
  }
  const dc = dijkstra(graph, [centre]);
  const radius = dc[argmax(dc)];
  const candidates = [];
  for (let v = 0; v < graph.count; ++v) {
    if (!Number.isFinite(dc[v]) || dc[v] < minRelative * radius) continue;
    let peak = true;
    for (let e = graph.offsets[v]; e < graph.offsets[v + 1] && peak; ++e) if (dc[graph.neighbours[e]] > dc[v]) peak = false;
    if (peak) candidates.push(v);
  }
  candidates.sort((x, y) => dc[y] - dc[x]);
  const covered = new Float64Array(graph.count).fill(Infinity);
  const extremities = [];
  const c = [positions[3 * centre], positions[3 * centre + 1], positions[3 * centre + 2]];
  for (const v of candidates) {
    if (extremities.length >= count) break;
    if (covered[v] < separation * radius) continue;
    dijkstra(graph, [v], { maxDistance: separation * radius, into: covered });
    const d = [positions[3 * v] - c[0], positions[3 * v + 1] - c[1], positions[3 * v + 2] - c[2]];
    const norm = Math.hypot(...d) || 1;
    extremities.push({ vertex: v, relative: dc[v] / radius, direction: d.map((x) => x / norm) });
  }
  // Vertex areas (a third of each incident triangle) for the bulk below.
  const area = new Float64Array(graph.count);
  let total = 0;
  for (let t = 0; t + 2 < triangles.length; t += 3) {
    const a = 3 * triangles[t];
    const b = 3 * triangles[t + 1];
    const c = 3 * triangles[t + 2];
    const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1], uz = positions[b + 2] - positions[a + 2];
    const wx = positions[c] - positions[a], wy = positions[c + 1] - positions[a + 1], wz = positions[c + 2] - positions[a + 2];
    const A = 0.5 * Math.hypot(uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx);
    area[a / 3] += A / 3;
    area[b / 3] += A / 3;
    area[c / 3] += A / 3;
    total += A;
  }
  // One Dijkstra per extremity gives both its geodesic distances to the others and its bulk: the
  // share of the surface within `bulkRadius` × radius of it (a head is bulkier than a paw
  // whatever the pose; geodesic, so the pose does not change it).
  const n = extremities.length;
  const between = new Array(n * n).fill(0);
  extremities.forEach((e, i) => {
    const d = dijkstra(graph, [e.vertex]);
    extremities.forEach((f, j) => { between[i * n + j] = d[f.vertex] / radius; });
    let sum = 0;
    for (let v = 0; v < graph.count; ++v) if (d[v] <= bulkRadius * radius) sum += area[v];
    e.bulk = total > 0 ? sum / total : 0;
  });
  return { centre, radius, extremities, between };
}

// Pairs of extremities of two meshes (findExtremities results): [{reference, source, cost}]
// (vertex indices), each extremity in at most one pair. The assignment is chosen as a whole,
// by what does not change with the pose: every pair costs the difference of its ends' relative
// distances from the centre plus the mean difference of its geodesic distances to the other
// pairs' ends (`between`); the directions from the centre only break ties (mirror-symmetric
// limbs: left vs right), with a small weight, since a posed reference (a lion standing up, paws
// raised) points its limbs elsewhere. An extremity left unpaired costs `unpaired`. Exhaustive
// over partial injective maps (≤ 8 extremities a side: ~1.4M assignments at most). Then the
// pairs must agree with each other intrinsically: the pair whose geodesic distances to the other
// pairs' ends differ most between the meshes (mean relative difference over `maxDistortion`) is
// dropped, until all agree.
export function matchExtremities(referenceSet, sourceSet, { maxDistortion = 0.2, direction = 0.15, unpaired = 0.7, bulk = 0.4 } = {}) {
  // The search is exhaustive: at most the 8 farthest extremities of each side take part.
  const reference = referenceSet.extremities.slice(0, 8);
  const source = sourceSet.extremities.slice(0, 8);
  const nr = referenceSet.extremities.length;
  const ns = sourceSet.extremities.length;
  const unary = (i, j) => {
    const r = reference[i].direction;
    const t = source[j].direction;
    const b = reference[i].bulk > 0 && source[j].bulk > 0 ? Math.abs(Math.log(reference[i].bulk / source[j].bulk)) : 0;
    return Math.abs(reference[i].relative - source[j].relative) + bulk * b + direction * Math.hypot(r[0] - t[0], r[1] - t[1], r[2] - t[2]);
  };
  const delta = (i, j, k, l) => Math.abs(referenceSet.between[i * nr + k] - sourceSet.between[j * ns + l]);
  const ri = [];
  const sj = [];
  const usedS = new Uint8Array(source.length);
  const most = Math.min(reference.length, source.length);
  let best = { cost: unpaired * most, ri: [], sj: [] };
  const search = (i, unarySum, pairSum) => {
    const m = ri.length;
    const cost = unarySum + (m > 1 ? (2 * pairSum) / (m - 1) : 0) + unpaired * (most - m);
    if (cost < best.cost - 1e-12) best = { cost, ri: ri.slice(), sj: sj.slice() };
    if (i >= reference.length || m >= most) return;
    search(i + 1, unarySum, pairSum); // reference extremity i unpaired
    for (let j = 0; j < source.length; ++j) {
      if (usedS[j]) continue;
      let add = 0;
      for (let q = 0; q < m; ++q) add += delta(i, j, ri[q], sj[q]);
      usedS[j] = 1;
      ri.push(i);
      sj.push(j);
      search(i + 1, unarySum + unary(i, j), pairSum + add);
      ri.pop();
      sj.pop();
      usedS[j] = 0;
    }
  };
  search(0, 0, 0);
  const pairs = best.ri.map((i, k) => ({ i, j: best.sj[k], reference: reference[i].vertex, source: source[best.sj[k]].vertex, cost: unary(i, best.sj[k]) }));
  pairs.sort((x, y) => x.cost - y.cost);
  for (;;) {
    if (pairs.length < 3) break;
    let worst = -1;
    let worstDistortion = 0;
    pairs.forEach((p, a) => {
      let sum = 0;
      for (const q of pairs) if (q !== p) sum += Math.abs(referenceSet.between[p.i * nr + q.i] - sourceSet.between[p.j * ns + q.j]);
      const distortion = sum / (pairs.length - 1);
      if (distortion > worstDistortion) { worstDistortion = distortion; worst = a; }
    });
    if (worstDistortion <= maxDistortion) break;
    pairs.splice(worst, 1);
  }
  return pairs.map(({ reference: r, source: s, cost }) => ({ reference: r, source: s, cost }));
}
