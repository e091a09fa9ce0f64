// The page's edit helpers without a browser: vertex sets on the welded mesh (adjacency,
// grow / shrink), the selection with numbered handles, the edit spec the page builds, saves and reads back, and the latest-only
// drag pump (one request in flight, the newest value next, never a queue of stale ones).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { EditSelection } from '../../web/src/lib/edit-selection.js';
import { buildSpec, identity, readSpec } from '../../web/src/lib/edit-spec.js';
import { LatestOnly } from '../../web/src/lib/latest-only.js';
import { grow, members, setFromIndices, shrink, vertexAdjacency, weldedTriangles } from '../../web/src/lib/vertex-sets.js';

// A strip of 2×n quads split into triangles: vertices (i, j), i < n + 1, j < 2, index 2i + j.
function strip(n) {
  const t = [];
  for (let i = 0; i < n; ++i) {
    const a = 2 * i;
    t.push(a, a + 2, a + 1, a + 1, a + 2, a + 3);
  }
  return new Uint32Array(t);
}

test('adjacency, grow and shrink by one ring on a strip', () => {
  const adjacency = vertexAdjacency(strip(5), 12);
  const neighbours = (v) => Array.from(adjacency.neighbors.subarray(adjacency.offsets[v], adjacency.offsets[v + 1]));
  assert.deepEqual(neighbours(0), [1, 2]);
  assert.deepEqual(neighbours(4), [2, 3, 5, 6]);
  const set = setFromIndices([4, 5], 12);
  grow(set, adjacency);
  assert.deepEqual(members(set), [2, 3, 4, 5, 6, 7]);
  shrink(set, adjacency);
  assert.deepEqual(members(set), [4, 5]);
  shrink(set, adjacency);
  assert.deepEqual(members(set), []);
  assert.throws(() => setFromIndices([12], 12), /outside/);
});

test('welded triangles join split (seam) vertices', () => {
  // Two triangles sharing an edge whose vertices are duplicated in the raw layout.
  const raw = new Uint32Array([0, 1, 2, 3, 4, 5]);
  const toWelded = new Uint32Array([0, 1, 2, 2, 1, 3]);
  const t = weldedTriangles(raw, toWelded);
  assert.deepEqual(Array.from(t), [0, 1, 2, 2, 1, 3]);
  const a = vertexAdjacency(t, 4);
  assert.deepEqual(Array.from(a.neighbors.subarray(a.offsets[1], a.offsets[2])), [0, 2, 3]);
});

test('the spec the page saves reads back to the same edit', () => {
  const matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0.25, 0, 1];
  const spec = buildSpec({ handles: [[3, 4], [7]], fixed: [0], matrices: [matrix, identity], features: 'scale', options: { coherence_rings: 1 } });
  assert.deepEqual(spec, {
    handles: [{ select: [3, 4], matrix }, { select: [7], matrix: identity }], fixed: [0], features: 'scale', options: { coherence_rings: 1 },
  });
  const back = readSpec(JSON.parse(JSON.stringify(spec)));
  assert.deepEqual(back, { handles: [[3, 4], [7]], roi: [], fixed: [0], matrices: [matrix, identity], features: 'scale', options: { coherence_rings: 1 } });
  assert.deepEqual(buildSpec({ handles: [[1]] }), { handles: [{ select: [1] }], features: 'keep' });
  assert.deepEqual(readSpec({ handles: [{ select: [1] }] }).matrices, [identity]);
  assert.deepEqual(readSpec({ handles: [{ select: { indices: [1] } }], roi: [1, 2] }).roi, [1, 2]);
  assert.throws(() => readSpec({ handles: [{ select: { spheres: [] } }] }), /index lists/);
  assert.throws(() => readSpec({ handles: [{ select: [1], translate: [0, 1, 0] }] }), /matrix/);
  assert.throws(() => readSpec({ handles: [] }), /handles/);
});

test('latest-only pump: one request in flight, the newest value next', async () => {
  const sent = [];
  const answers = [];
  let release = null;
  const pump = new LatestOnly((value) => {
    sent.push(value);
    return new Promise((resolve) => { release = () => resolve(value * 10); });
  }, { onAnswer: (answer) => answers.push(answer) });
  pump.push(1);
  pump.push(2);
  pump.push(3);
  pump.push(4);
  await new Promise((r) => setTimeout(r, 0));
  assert.deepEqual(sent, [1]);       // 2, 3, 4 wait; only the newest survives
  release();
  await new Promise((r) => setTimeout(r, 0));
  assert.deepEqual(sent, [1, 4]);
  const idle = pump.idle();
  release();
  await idle;
  assert.deepEqual(answers, [10, 40]);
  assert.equal(pump.sent, 2);
  assert.equal(pump.answered, 2);
});

test('latest-only pump keeps working after a failed request', async () => {
  const errors = [];
  const pump = new LatestOnly(async (v) => { if (v === 1) throw new Error('boom'); return v; }, { onError: (e) => errors.push(e.message) });
  pump.push(1);
  await pump.idle();
  pump.push(2);
  await pump.idle();
  assert.deepEqual(errors, ['boom']);
  assert.equal(pump.answered, 1);
});

test('selection: handles never overlap each other or the fixed set; lists compact empty handles', () => {
  const adjacency = vertexAdjacency(strip(5), 12);
  const s = new EditSelection(12);
  assert.ok(s.paint([0, 1], 'handle', 0, false));
  assert.equal(s.addHandle(), 1);
  assert.equal(s.addHandle(), 1); // the new one is still empty: no third handle
  s.paint([10, 11], 'handle', 1, false);
  s.paint([11, 9], 'fixed', 0, false); // takes 11 from handle 2
  assert.deepEqual(s.counts(), { handle: 3, handles: [2, 1], fixed: 2, roi: 0 });
  s.change('handle', 0, (m) => grow(m, adjacency)); // handle 1 grows into free vertices only
  assert.deepEqual(s.handleMembers(0), [0, 1, 2, 3]);
  assert.ok(s.paint([9], 'fixed', 0, true));
  assert.ok(!s.paint([9], 'fixed', 0, true));
  s.change('handle', 0, (m) => m.fill(0));
  assert.deepEqual(s.lists(), { handles: [[10]], roi: [], fixed: [11] });
  assert.equal(s.compact(1), 0);
  assert.deepEqual(s.handleMembers(0), [10]);
  const back = EditSelection.fromLists({ handles: [[0], [5, 6]], fixed: [6, 7] }, 12);
  assert.deepEqual(back.lists(), { handles: [[0], [5, 6]], roi: [], fixed: [7] });
});
