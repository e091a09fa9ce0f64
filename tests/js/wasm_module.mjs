// Shared by the JS API tests: loads the node build of the wasm module (meshmorph_node.cjs from
// MM_WASM_DIR, default build/wasm/wasm) once per test file and builds the same `ctx` the
// worker hands to its ops (web/src/worker/worker.js), so the tests call the bindings exactly as the
// page does.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
export const wasmDir = path.resolve(repoDir, process.env.MM_WASM_DIR || 'build/wasm/wasm');

let modulePromise = null;

export function loadModule() {
  if (!modulePromise) {
    const file = path.join(wasmDir, 'meshmorph_node.cjs');
    if (!fs.existsSync(file)) throw new Error(`${file} is missing: build the wasm target meshmorph_node (or set MM_WASM_DIR)`);
    const require = createRequire(import.meta.url);
    const createMeshMorph = require(file);
    // Built with WASM_ASYNC_COMPILATION=0: the factory returns the module, not a Promise;
    // `await` handles both.
    modulePromise = Promise.resolve(createMeshMorph());
  }
  return modulePromise;
}

// A fresh worker-like context: module + per-worker state + a progress sink.
export async function makeContext(progress = () => true) {
  return { module: await loadModule(), state: { meshes: new Map() }, progress };
}

export function dataBytes(relative) {
  return new Uint8Array(fs.readFileSync(path.join(repoDir, 'data', relative)));
}

export function readGolden(name) {
  const file = path.join(repoDir, 'tests/golden', `${name}.json`);
  if (!fs.existsSync(file)) throw new Error(`missing golden file ${file} (the C++ suite writes it with --update-golden)`);
  return JSON.parse(fs.readFileSync(file, 'utf8'));
}

// Buffers as the worker receives them: {[file name]: bytes}.
export function fileBuffers(relative, siblings = []) {
  const dir = path.posix.dirname(relative);
  const buffers = { [path.posix.basename(relative)]: dataBytes(relative) };
  for (const s of siblings) buffers[s] = dataBytes(path.posix.join(dir, s));
  return buffers;
}
