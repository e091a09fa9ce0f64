// Every GLB the C++ tests wrote (roundtrip_*.glb and save_mesh_*.glb in the scratch directory)
// must pass the Khronos glTF-Validator with 0 errors.
//   MM_SCRATCH_DIR=<build>/tests/test-scratch node --test tests/js/gltf_validator.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

const scratch = process.env.MM_SCRATCH_DIR;

function glbFiles() {
  assert.ok(scratch, 'set MM_SCRATCH_DIR to the scratch directory of a meshmorph_tests run');
  assert.ok(fs.existsSync(scratch), `MM_SCRATCH_DIR ${scratch} does not exist: run meshmorph_tests first`);
  return fs.readdirSync(scratch).filter((f) => f.endsWith('.glb')).sort();
}

test('the C++ tests wrote GLBs to validate', () => {
  const files = glbFiles();
  assert.ok(files.some((f) => f.startsWith('roundtrip_')),
    `no roundtrip_*.glb in ${scratch}: run meshmorph_tests --gtest_filter='Io*' first`);
  assert.ok(files.some((f) => f.startsWith('save_mesh_')), `no save_mesh_*.glb in ${scratch}`);
});

for (const file of scratch && fs.existsSync(scratch) ? glbFiles() : []) {
  test(`${file} passes glTF-Validator with 0 errors`, async () => {
    const bytes = new Uint8Array(fs.readFileSync(path.join(scratch, file)));
    const report = await validator.validateBytes(bytes, {
      uri: file,
      maxIssues: 0,
      // A GLB we write must be self-contained.
      externalResourceFunction: (uri) => Promise.reject(new Error(`unexpected external resource ${uri}`)),
    });
    const errors = report.issues.messages.filter((m) => m.severity === 0);
    assert.equal(report.issues.numErrors, 0,
      `${file}: ${errors.map((e) => `${e.code} ${e.pointer ?? ''}: ${e.message}`).slice(0, 10).join('\n')}`);
  });
}
