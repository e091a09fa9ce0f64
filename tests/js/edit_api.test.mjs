// API tests of wasm/bind_edit.cpp through web/src/worker/ops/edit.js — the functions the worker runs —
// with the node build of the module (node --test tests/js/; MM_WASM_DIR overrides the build
// directory). The golden is the one the C++ suite checks natively and in wasm
// (tests/edit_test.cpp, Edit.GoldenBarBend).
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { MeshMorphError } from '../../web/src/lib/errors.js';
import { ops as meshOps } from '../../web/src/worker/ops/mesh.js';
import { ops as editOps } from '../../web/src/worker/ops/edit.js';
import { fileBuffers, makeContext, readGolden } from './wasm_module.mjs';

function expectCode(fn, code, messagePattern) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof MeshMorphError, `expected a MeshMorphError, got ${e}`);
    assert.equal(e.code, code, `code of "${e.message}"`);
    if (messagePattern) assert.match(e.message, messagePattern);
    return true;
  });
}

// The bend of tests/edit_test_util.h bar_case(true): lowest/highest 10% along the long axis are
// fixed/handle; the handle turns 90° and moves along a quarter circle of the same length.
function barBend(V) {
  const n = V.length / 3;
  const lo = [0, 1, 2].map((a) => Math.min(...Array.from({ length: n }, (_, i) => V[3 * i + a])));
  const hi = [0, 1, 2].map((a) => Math.max(...Array.from({ length: n }, (_, i) => V[3 * i + a])));
  const ext = hi.map((h, a) => h - lo[a]);
  const ax = ext.indexOf(Math.max(...ext));
  const up = (ax + 1) % 3;
  const c0 = [0, 0, 0], ch = [0, 0, 0];
  let n0 = 0, nh = 0;
  for (let i = 0; i < n; i++) {
    const t = (V[3 * i + ax] - lo[ax]) / ext[ax];
    if (t <= 0.1) { n0++; for (let a = 0; a < 3; a++) c0[a] += V[3 * i + a]; }
    if (t >= 0.9) { nh++; for (let a = 0; a < 3; a++) ch[a] += V[3 * i + a]; }
  }
  for (let a = 0; a < 3; a++) { c0[a] /= n0; ch[a] /= nh; }
  const L = Math.hypot(ch[0] - c0[0], ch[1] - c0[1], ch[2] - c0[2]);
  const rho = L / (Math.PI / 2);
  const target = [...c0];
  target[ax] += rho;
  target[up] += rho;
  // Rotation by 90° about axis × up maps the long axis onto `up`: R e_ax = e_up, R e_up = -e_ax.
  const R = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  R[ax][ax] = 0; R[up][up] = 0; R[up][ax] = 1; R[ax][up] = -1;
  // x ↦ target + R (x − ch): translation t = target − R ch.
  const t = [0, 1, 2].map((r) => target[r] - (R[r][0] * ch[0] + R[r][1] * ch[1] + R[r][2] * ch[2]));
  const matrix = [];
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) matrix.push(r === 3 ? (c === 3 ? 1 : 0) : c === 3 ? t[r] : R[r][c]);
  const axisName = 'xyz'[ax];
  const spec = {
    fixed: { slabs: [{ axis: axisName, from: 0, to: 0.1 }] },
    handles: [{ select: { slabs: [{ axis: axisName, from: 0.9, to: 1 }] } }],
  };
  return { spec, matrix };
}

test('edit session: create, drag many times, finalize, dispose — matches the C++ golden', async () => {
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'bar.ply' }, fileBuffers('edit/bar.ply'));
  const mesh = ctx.state.meshes.get('main');
  const { spec, matrix } = barBend(mesh.weldedPositions);
  const progress = [];
  ctx.progress = (stage, fraction) => { progress.push(fraction); return true; };
  const created = editOps.editCreate(ctx, { spec });
  assert.equal(created.info.handles.length, 1);
  assert.ok(created.info.stats.free_vertices > 0);
  assert.equal(created.info.features, 'keep');
  assert.deepEqual(created.info.transforms[0], [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  assert.equal(progress.at(-1), 1);

  // Identity drag returns the input; several drags reuse the factorization.
  const identity = editOps.editDrag(ctx, { transforms: [{}] });
  assert.ok(identity.buffers.positions instanceof Float32Array);
  const W = mesh.weldedPositions;
  for (let i = 0; i < W.length; i++) assert.ok(Math.abs(identity.buffers.positions[i] - W[i]) < 1e-6);
  assert.equal(identity.buffers.rawPositions.length, mesh.toWelded.length * 3);
  editOps.editDrag(ctx, { transforms: [{ translate: [0, 0.1, 0] }] });
  const drag = editOps.editDrag(ctx, { transforms: [{ matrix }] });
  assert.equal(drag.buffers.positions.length, W.length);

  const fin = editOps.editFinalize(ctx, { mode: 'keep' });
  const golden = readGolden('edit_bar_bend');
  assert.equal(golden.rows * golden.cols, fin.buffers.positions.length);
  let worst = 0;
  for (let i = 0; i < golden.data.length; i++) worst = Math.max(worst, Math.abs(golden.data[i] - fin.buffers.positions[i]));
  // Float32 output: ~6e-8 relative rounding on top of the golden's 1e-7.
  assert.ok(worst <= 1e-6, `largest difference to the golden ${worst}`);

  assert.equal(editOps.editDispose(ctx, {}).info.disposed, true);
  expectCode(() => editOps.editDrag(ctx, { transforms: [{}] }), 'InvalidArgument', /no edit session/);
});

test('edit session errors come back as codes', async () => {
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'bar.ply' }, fileBuffers('edit/bar.ply'));
  expectCode(() => editOps.editCreate(ctx, { spec: { handles: [] } }), 'InvalidArgument', /non-empty/);
  expectCode(() => editOps.editCreate(ctx, { spec: '{ not json' }), 'ParseError');
  expectCode(() => editOps.editCreate(ctx, { spec: { handles: [{ select: [0], spin: 3 }] } }), 'ParseError', /spin/);
  editOps.editCreate(ctx, { spec: { handles: [{ select: { slabs: [{ axis: 'long', from: 0.9, to: 1 }] } }],
                                    fixed: { slabs: [{ axis: 'long', from: 0, to: 0.1 }] } } });
  expectCode(() => editOps.editDrag(ctx, { transforms: [{}, {}] }), 'InvalidArgument', /2 handle transforms for 1/);
  expectCode(() => editOps.editDrag(ctx, { transforms: [{ matrix: [1, 2, 3] }] }), 'ParseError', /16 numbers/);
  expectCode(() => editOps.editFinalize(ctx, {}), 'InvalidArgument', /before a drag/);
  expectCode(() => editOps.editFinalize(ctx, { mode: 'big' }), 'InvalidArgument');
  // A cancelled precompute leaves no session behind.
  ctx.progress = () => false;
  expectCode(() => editOps.editCreate(ctx, { spec: { handles: [{ select: [0, 1, 2] }] } }), 'Cancelled');
  expectCode(() => editOps.editDrag(ctx, { transforms: [{}] }), 'InvalidArgument', /no edit session/);
});
