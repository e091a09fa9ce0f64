// scripts/bench-table.mjs: peer figures parsed from PEERS.md's text, and repeated runs
// (scripts/bench --repeat N) joined row by row to their fastest.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { fastestRows, peerMs } from '../../scripts/bench-table.mjs';

test('peer figures: ms, s and sums of a paper\'s stages', () => {
  assert.equal(peerMs('igl 8 ms'), 8);
  assert.equal(peerMs('Spectra+LDLT 1.56 s'), 1560);
  assert.ok(Math.abs(peerMs('paper 001: 0.062 + 0.328 + 0.032 s') - 422) < 1e-9);
  assert.equal(peerMs('(no peer equivalent)'), null);
});

test('repeated runs: every row its fastest run, in the first run\'s order', () => {
  const row = (stage, ms, note = '') => ({ suite: 's', mesh: 'm', stage, ms, note });
  const runs = [
    [row('a', 10, 'first'), row('b', 5)],
    [row('a', 8, 'second'), row('b', 7), row('c', 1)],
    [row('b', 6)],
  ];
  const rows = fastestRows(runs);
  assert.deepEqual(rows.map((r) => [r.stage, r.ms, r.note]), [['a', 8, 'second'], ['b', 5, ''], ['c', 1, '']]);
  assert.deepEqual(fastestRows([[row('x', 3)]]), [row('x', 3)]);
});
