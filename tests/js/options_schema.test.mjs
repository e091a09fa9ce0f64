// One options schema per job (app/option_schema.h): the native CLI's `--help` lists every option
// with the schema's default, and the wasm module's optionSchema() (what the page builds its
// options panels from) equals the native CLI's `meshmorph options --json`.
// Run: node --test tests/js/ (MM_CLI overrides build/native/native/meshmorph).
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { loadModule, repoDir } from './wasm_module.mjs';

const cli = process.env.MM_CLI || path.join(repoDir, 'build/native/native/meshmorph');
const jobs = ['edit', 'merge', 'transfer', 'transfer-parts', 'retarget', 'joints'];
// Schemas that are not commands of their own: their flags are listed in another command's --help.
const helpOf = { 'transfer-parts': 'transfer' };

function nativeSchemas() {
  return JSON.parse(execFileSync(cli, ['options', '--json'], { encoding: 'utf8' })).jobs;
}

test('the CLI is built', () => {
  assert.ok(fs.existsSync(cli), `${cli} is missing: build native first (scripts/build native)`);
});

test('CLI --help of every job shows each schema option with its default', () => {
  for (const schema of nativeSchemas()) {
    const help = execFileSync(cli, [helpOf[schema.job] ?? schema.job, '--help'], { encoding: 'utf8' });
    assert.ok(schema.options.length > 5, `${schema.job}: too few options`); // transfer-parts has 8
    for (const o of schema.options) {
      const line = help.split('\n').findIndex((l) => l.trimStart().startsWith(`${o.flag} `));
      assert.ok(line >= 0, `${schema.job} --help lacks ${o.flag}`);
      // The help may wrap after a long flag: look at this line and the next.
      const text = help.split('\n').slice(line, line + 2).join(' ');
      const shown = o.kind === 'choice' || o.kind === 'text' ? String(o.default) : String(o.default);
      assert.ok(text.includes(`(default ${shown === '' ? 'none' : shown}`),
        `${schema.job} ${o.flag}: help says "${text.trim()}", schema default ${JSON.stringify(o.default)}`);
    }
  }
});

test('the wasm module and the native CLI describe the same options', async () => {
  const module = await loadModule();
  const native = nativeSchemas();
  assert.deepEqual(native.map((s) => s.job), jobs);
  for (const n of native) {
    const r = module.optionSchema(n.job);
    assert.equal(r.ok, true);
    assert.deepEqual(r.schema, n);
  }
  const bad = module.optionSchema('juggle');
  assert.equal(bad.ok, false);
  assert.equal(bad.code, 'InvalidArgument');
});

test('the wasm bindings reject options the schema does not know, naming them', async () => {
  const module = await loadModule();
  const tri = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
  const idx = new Uint32Array([0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2]);
  const r = module.poseTransfer(tri, idx, tri, idx, new Int32Array(0), { lambda_one: 0.1 }, undefined, undefined, undefined);
  assert.equal(r.ok, false);
  assert.equal(r.code, 'InvalidArgument');
  assert.match(r.message, /lambda_one/);
  const range = module.poseTransfer(tri, idx, tri, idx, new Int32Array(0), { cage_vertices: 2 }, undefined, undefined, undefined);
  assert.equal(range.ok, false);
  assert.match(range.message, /cage_vertices/);
});

test('partTransfer rejects unknown part options and malformed part files before any work', async () => {
  const module = await loadModule();
  const tri = new Float64Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
  const idx = new Uint32Array([0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2]);
  const r = module.partTransfer(tri, idx, tri, idx, new Int32Array(0), 'auto', {}, { seam_ringz: 2 }, undefined);
  assert.equal(r.ok, false);
  assert.equal(r.code, 'InvalidArgument');
  assert.match(r.message, /seam_ringz/);
  const bad = module.partTransfer(tri, idx, tri, idx, new Int32Array(0), '{"parts": 3}', {}, {}, undefined);
  assert.equal(bad.ok, false);
  assert.equal(bad.code, 'ParseError');
});

test('the worker op optionSchema returns the schema the bindings use', async () => {
  const { ops } = await import('../../web/src/worker/ops/mesh.js');
  const { makeContext } = await import('./wasm_module.mjs');
  const ctx = await makeContext();
  const r = ops.optionSchema(ctx, { job: 'transfer' });
  const names = r.info.options.map((o) => o.name);
  assert.ok(names.includes('cage_vertices') && names.includes('lambda1'), names.join(','));
  assert.equal(r.info.options.find((o) => o.name === 'cage_vertices').default, 450);
  assert.throws(() => ops.optionSchema(ctx, { job: 'nope' }), /no job named/);
});
