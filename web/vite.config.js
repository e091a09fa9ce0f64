// Vite build of the page. Root is web/; output goes to build/web-dist (never committed).
//
// - The wasm module is imported from the CMake build (`@meshmorph/wasm/meshmorph_web.mjs`,
//   default build/wasm/wasm, override with MM_WASM_DIR). Its glue locates the .wasm with
//   `new URL('meshmorph_web.wasm', import.meta.url)`, which Vite turns into a hashed asset.
// - Gallery samples (web/src/lib/samples.js) and the Retarget job's characters and joints files
//   (web/src/lib/clip-library.js) are served from data/ by the dev server and copied
//   into the build under samples/, with data/licenses/.
// - The threaded wasm modules (`meshmorph_web_mt.*`, beside the single-threaded ones in
//   build/wasm/wasm; override with MM_WASM_MT_DIR) is served and copied as plain files under wasm-mt/: its pthread workers load
//   the glue again by URL, so Vite must not bundle it. Missing, the page runs single-threaded.
// - COOP/COEP headers make the page crossOriginIsolated, so SharedArrayBuffer exists (Cancel
//   stops a computation without killing the worker, see web/src/lib/client.js, and the threaded
//   module can share its memory).
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { defineConfig } from 'vite';
import { libraryFiles } from './src/lib/clip-library.js';
import { sampleFiles } from './src/lib/samples.js';

const webDir = path.dirname(fileURLToPath(import.meta.url));
const repoDir = path.resolve(webDir, '..');
const dataDir = path.join(repoDir, 'data');
const wasmDir = path.resolve(repoDir, process.env.MM_WASM_DIR || 'build/wasm/wasm');
const wasmThreadedDir = path.resolve(repoDir, process.env.MM_WASM_MT_DIR || 'build/wasm/wasm');

const isolationHeaders = {
  'Cross-Origin-Opener-Policy': 'same-origin',
  'Cross-Origin-Embedder-Policy': 'require-corp',
};

const contentTypes = {
  '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json', '.bin': 'application/octet-stream',
  '.png': 'image/png', '.jpg': 'image/jpeg', '.ply': 'application/octet-stream',
  '.obj': 'text/plain', '.off': 'text/plain', '.md': 'text/plain; charset=utf-8', '.json': 'application/json', '.txt': 'text/plain; charset=utf-8',
};

function licenseFiles() {
  return fs.readdirSync(path.join(dataDir, 'licenses')).map((f) => `licenses/${f}`);
}

// Only listed files are reachable (no path traversal into the repository).
function meshmorphSamples() {
  const allowed = () => new Set([...sampleFiles(), ...libraryFiles(), ...licenseFiles()]);
  return {
    name: 'meshmorph-samples',
    configureServer(server) {
      server.middlewares.use('/samples/', (req, res, next) => {
        const rel = decodeURIComponent((req.url || '').split('?')[0]).replace(/^\/+/, '');
        if (!allowed().has(rel)) return next();
        res.setHeader('Content-Type', contentTypes[path.extname(rel)] || 'application/octet-stream');
        fs.createReadStream(path.join(dataDir, rel)).pipe(res);
      });
    },
    generateBundle() {
      for (const rel of allowed()) {
        this.emitFile({ type: 'asset', fileName: `samples/${rel}`, source: fs.readFileSync(path.join(dataDir, rel)) });
      }
    },
  };
}

const threadedFiles = ['meshmorph_web_mt.mjs', 'meshmorph_web_mt.wasm', 'meshmorph_web_mt.worker.js'];
const threadedTypes = { '.mjs': 'text/javascript', '.js': 'text/javascript', '.wasm': 'application/wasm' };

function meshmorphThreadedModule() {
  const present = () => threadedFiles.every((f) => fs.existsSync(path.join(wasmThreadedDir, f)));
  return {
    name: 'meshmorph-threaded-module',
    configureServer(server) {
      server.middlewares.use('/wasm-mt/', (req, res, next) => {
        const rel = decodeURIComponent((req.url || '').split('?')[0]).replace(/^\/+/, '');
        if (!threadedFiles.includes(rel) || !fs.existsSync(path.join(wasmThreadedDir, rel))) return next();
        for (const [k, v] of Object.entries(isolationHeaders)) res.setHeader(k, v);
        res.setHeader('Content-Type', threadedTypes[path.extname(rel)]);
        fs.createReadStream(path.join(wasmThreadedDir, rel)).pipe(res);
      });
    },
    generateBundle() {
      if (!present()) {
        this.warn(`${wasmThreadedDir} has no threaded build (scripts/build wasm): the page will run on one thread`);
        return;
      }
      for (const f of threadedFiles) {
        this.emitFile({ type: 'asset', fileName: `wasm-mt/${f}`, source: fs.readFileSync(path.join(wasmThreadedDir, f)) });
      }
    },
  };
}

// A missing wasm build otherwise surfaces as an obscure resolve error deep in the worker.
function requireWasmBuild() {
  return {
    name: 'meshmorph-require-wasm',
    buildStart() {
      const glue = path.join(wasmDir, 'meshmorph_web.mjs');
      if (!fs.existsSync(glue)) {
        this.error(`${glue} is missing: build the wasm module first ` +
          '(emcmake cmake -S . -B build/wasm … && cmake --build build/wasm --target meshmorph_web), or set MM_WASM_DIR');
      }
    },
  };
}

export default defineConfig({
  root: webDir,
  base: './',
  publicDir: false,
  resolve: { alias: { '@meshmorph/wasm': wasmDir } },
  plugins: [requireWasmBuild(), meshmorphSamples(), meshmorphThreadedModule()],
  worker: { format: 'es' },
  build: {
    outDir: path.join(repoDir, 'build/web-dist'),
    emptyOutDir: true,
    target: 'es2022',
    // three.js alone is ~530 kB minified; one chunk is fine for this page.
    chunkSizeWarningLimit: 1000,
  },
  server: { headers: isolationHeaders, fs: { allow: [webDir, wasmDir, path.join(repoDir, 'node_modules')] } },
  preview: { headers: isolationHeaders },
});
