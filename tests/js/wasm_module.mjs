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
// The threaded build (-pthread, scripts/build wasm): MM_WASM_THREADED=1 runs the tests on it.
export const wasmThreadedDir = path.resolve(repoDir, process.env.MM_WASM_MT_DIR || 'build/wasm/wasm');
const threadedByDefault = process.env.MM_WASM_THREADED === '1';

const modules = new Map(); // variant → Promise<module>

// The node build of the module: 'single' (meshmorph_node.cjs) or 'threaded' (meshmorph_node_mt.cjs);
// the default is the single-threaded one unless MM_WASM_THREADED=1.
export function loadModule(variant = threadedByDefault ? 'threaded' : 'single') {
  if (!modules.has(variant)) {
    const threaded = variant === 'threaded';
    const file = threaded ? path.join(wasmThreadedDir, 'meshmorph_node_mt.cjs') : path.join(wasmDir, 'meshmorph_node.cjs');
    if (!fs.existsSync(file)) {
      throw new Error(`${file} is missing: build the wasm target meshmorph_node (scripts/build wasm; or set ${threaded ? 'MM_WASM_MT_DIR' : 'MM_WASM_DIR'})`);
    }
    const require = createRequire(import.meta.url);
    const createMeshMorph = require(file);
    // The single-threaded build compiles synchronously: the factory returns the module. The
    // threaded one compiles asynchronously (its pthread glue needs the factory's Promise) and is
    // handed its .wasm bytes (node 20's fetch() cannot read a path); its runtime is up once
    // `ready` resolves, after the pthread pool has loaded.
    const made = threaded ? createMeshMorph({ wasmBinary: fs.readFileSync(file.replace(/\.cjs$/, '.wasm')) }) : createMeshMorph();
    // Node keeps running while a worker thread is referenced: the pool's idle workers are
    // unref'd so a test file ends when its tests do (a running pthread is always joined by the
    // calling thread, which keeps the process alive meanwhile).
    const unrefPool = (module) => {
      for (const w of module.PThread?.unusedWorkers || []) w.unref?.();
      return module;
    };
    modules.set(variant, Promise.resolve(made.ready || made).then(unrefPool));
  }
  return modules.get(variant);
}

// A fresh worker-like context: module + per-worker state + a progress sink.
export async function makeContext(progress = () => true, variant = undefined) {
  return { module: await loadModule(variant), state: { meshes: new Map() }, progress };
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
