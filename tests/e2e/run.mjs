// Browser end-to-end tests of the page: playwright-core drives Debian's /usr/bin/chromium
// (headless, WebGL through SwiftShader) against the built page (build/web-dist; rebuilt here
// when missing, older than web/ or the wasm module, or MM_E2E_BUILD=1) served by `vite
// preview` on 127.0.0.1 and a free port.
// Screenshots (and the exported GLB) go to build/e2e/ or MM_E2E_OUT. Prints "N passed, M
// failed"; exit code 1 on any failure.
//
// Then the page basics, the glTF materials, Edit, Transfer and Retarget run again in Firefox ESR
// (tests/e2e/firefox.mjs; skipped with a message when firefox-esr or Xvfb is missing).
//
// Usage: node tests/e2e/run.mjs [--headed] [--only <substring>] [--no-firefox | --firefox-only]
// Env:   MM_CHROMIUM (default /usr/bin/chromium), MM_E2E_BUILD=1 (rebuild the page first),
//        MM_E2E_OUT (output directory), MM_WASM_DIR (the wasm build, as for vite.config.js),
//        MM_CLI (the native CLI the edit test compares with; default build/native/native/meshmorph),
//        MM_FIREFOX (default /usr/bin/firefox-esr)
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { spawnSync } from 'node:child_process';
import { chromium } from 'playwright-core';
import { build, preview } from 'vite';
import { writeBigMesh } from './big-mesh.mjs';
import { firefoxMissing, runInFirefox } from './firefox.mjs';
import { registerMergeTests } from './merge.mjs';
import { registerRetargetTests } from './retarget.mjs';
import { readPlyVertices } from './ply.mjs';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const configFile = path.join(repoDir, 'web/vite.config.js');
const distDir = path.join(repoDir, 'build/web-dist');
const shotDir = path.resolve(process.env.MM_E2E_OUT || path.join(repoDir, 'build/e2e'));
const args = process.argv.slice(2);
const only = args.includes('--only') ? args[args.indexOf('--only') + 1] : null;
const cliPath = path.resolve(repoDir, process.env.MM_CLI || 'build/native/native/meshmorph');
const background = [0x1d, 0x22, 0x30]; // web/src/view/viewer.js backgroundColor

// ---- helpers

function freePort() {
  return new Promise((resolve, reject) => {
    const server = net.createServer();
    server.unref();
    server.on('error', reject);
    server.listen(0, '127.0.0.1', () => {
      const { port } = server.address();
      server.close(() => resolve(port));
    });
  });
}

// Canvas pixels (downsampled to 200 px wide) read back in the page. The renderer keeps its
// drawing buffer (preserveDrawingBuffer), so drawImage sees the last frame.
async function canvasPixels(page) {
  return page.evaluate(() => {
    const src = document.getElementById('view');
    const w = 200;
    const h = Math.max(1, Math.round((w * src.height) / src.width));
    const c = document.createElement('canvas');
    c.width = w;
    c.height = h;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0, w, h);
    return { w, h, data: Array.from(g.getImageData(0, 0, w, h).data) };
  });
}

function pixelStats({ data }) {
  let foreground = 0;
  let coloured = 0;
  const n = data.length / 4;
  for (let i = 0; i < data.length; i += 4) {
    const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
    if (Math.abs(r - background[0]) + Math.abs(g - background[1]) + Math.abs(b - background[2]) > 30) {
      foreground += 1;
      if (Math.max(r, g, b) - Math.min(r, g, b) > 60) coloured += 1; // clearly red or blue, not grey
    }
  }
  return { foreground: foreground / n, coloured: coloured / n };
}

function pixelDifference(a, b) {
  let differ = 0;
  for (let i = 0; i < a.data.length; i += 4) {
    const d = Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2]);
    if (d > 40) differ += 1;
  }
  return differ / (a.data.length / 4);
}

function check(condition, message) {
  if (!condition) throw new Error(message);
}

async function shot(page, name) {
  await page.screenshot({ path: path.join(shotDir, `${name}.png`) });
}

// Waits until the page has drawn a frame showing its current state.
async function nextFrame(page) {
  await page.evaluate(() => window.__meshmorph.nextFrame());
}

async function waitIdle(page, timeout = 60000) {
  await page.waitForFunction(() => window.__meshmorph?.state.ready && !window.__meshmorph.state.busy, null, { timeout });
}

// Loads finished so far, once the page has settled (first sample shown, nothing running),
// so that a test started alone (--only) does not count the initial load as its own.
async function loadCount(page) {
  await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1, null, { timeout: 60000 });
  await waitIdle(page);
  return page.evaluate(() => window.__meshmorph.state.loads);
}

async function pickSample(page, id) {
  const loads = await loadCount(page);
  await page.selectOption('#sample', id);
  await page.waitForFunction((n) => window.__meshmorph.state.loads > n, loads, { timeout: 60000 });
  await waitIdle(page);
  await nextFrame(page);
}

async function computeBasis(page, k) {
  await loadCount(page);
  await page.selectOption('#eig-k', String(k));
  await page.click('#eig-run');
}

// Starts a long eigenbasis computation, waits until it reports progress, presses Cancel and
// expects the Cancelled error; returns how long the cancel took (ms).
async function cancelLongComputation(page, label) {
  await computeBasis(page, 100);
  await page.waitForFunction(() => window.__meshmorph.state.busy && document.getElementById('progress-bar').value > 0, null, { timeout: 60000 });
  await shot(page, `${label}-running`);
  const started = Date.now();
  await page.click('#cancel');
  await waitIdle(page, 15000);
  const elapsed = Date.now() - started;
  const error = await page.evaluate(() => window.__meshmorph.state.error);
  check(error?.code === 'Cancelled', `expected a Cancelled error, got ${JSON.stringify(error)}`);
  check(await page.isVisible('#error'), 'the cancel message is not shown');
  check(await page.evaluate(() => window.__meshmorph.state.eigen === null), 'a cancelled computation left a result');
  return elapsed;
}

// The page's long tasks (PerformanceObserver 'longtask', installed before the page's scripts by
// the runner): the longest one that overlaps [from, to] (page time, ms), 0 when none.
const longTaskTargetMs = 50;
async function longestTask(page, from, to) {
  return page.evaluate(({ a, b }) => (window.__longTasks === null ? -1 : window.__longTasks
    .filter((t) => t.start < b && t.start + t.duration > a)
    .reduce((m, t) => Math.max(m, t.duration), 0)), { a: from, b: to });
}

// Figures the run measured (printed at the end), per browser.
const measured = {};
const record = (browser, name, value) => { measured[`${name}${browser === 'firefox' ? ' [firefox]' : ''}`] = value; };

// ---- the tests (run in order; later ones build on the page state of earlier ones)

const tests = [];
const it = (name, fn) => tests.push({ name, fn });

it('page loads, worker and wasm module start', async ({ page, pageErrors }) => {
  await page.waitForFunction(() => window.__meshmorph?.state.ready, null, { timeout: 60000 });
  const mode = await page.evaluate(() => window.__meshmorph.cancelMode);
  check(mode === 'cooperative', `page is not crossOriginIsolated (cancel mode ${mode}); COOP/COEP headers missing?`);
  // Isolated: the threaded wasm build (web/src/worker/worker.js), with its pthread pool up.
  const threads = await page.evaluate(() => window.__meshmorph.threads);
  check(threads.threaded === true && threads.maxThreads >= 1, `the isolated page did not start the threaded module: ${JSON.stringify(threads)}`);
  check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
});

// The same page from a server without COOP/COEP (no SharedArrayBuffer): the single-threaded
// module, cancel by terminating the worker, and a computation still runs. Chromium only (the
// Firefox runner drives one page).
it('threads: without cross-origin isolation the page falls back to the single-threaded module', async ({ context }) => {
  const server = await plainServer(path.join(repoDir, 'build/web-dist'));
  const page = await context.newPage();
  try {
    await page.goto(`http://127.0.0.1:${server.address().port}/`);
    await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1 || window.__meshmorph?.state.error, null, { timeout: 60000 });
    const state = await page.evaluate(() => ({
      isolated: window.crossOriginIsolated, threads: window.__meshmorph.threads, cancel: window.__meshmorph.cancelMode,
      status: document.getElementById('status').textContent, error: window.__meshmorph.state.error,
    }));
    check(!state.isolated && !state.threads.threaded && state.threads.maxThreads === 1 && state.cancel === 'terminate' && !state.error,
      `not the single-threaded fallback: ${JSON.stringify(state)}`);
    await computeBasis(page, 10);
    await page.waitForFunction(() => window.__meshmorph.state.eigen?.k === 10 || window.__meshmorph.state.error, null, { timeout: 60000 });
    check(await page.evaluate(() => window.__meshmorph.state.eigen?.k === 10), `no eigenbasis: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
    check(/one thread/.test(await page.textContent('#status')) || /one thread/.test(state.status), `status does not say one thread: ${state.status}`);
    await shot(page, '00-no-isolation-one-thread');
  } finally {
    await page.close();
    await new Promise((resolve) => server.close(resolve));
  }
});

it('the default sample mesh renders (canvas not blank)', async ({ page }) => {
  await page.waitForFunction(() => window.__meshmorph.state.loads >= 1, null, { timeout: 60000 });
  await waitIdle(page);
  await nextFrame(page);
  const stats = pixelStats(await canvasPixels(page));
  await shot(page, '01-default-sample');
  check(stats.foreground > 0.04, `only ${(stats.foreground * 100).toFixed(1)}% of the canvas differs from the background`);
  const info = await page.textContent('#info');
  check(/skull\.ply/.test(info) && /vertices/.test(info), `info panel does not show the report: ${info.slice(0, 200)}`);
});

it('a PLY file opens through the file picker', async ({ page }) => {
  const loads = await loadCount(page);
  await page.setInputFiles('#file', path.join(repoDir, 'data/edit/armadillo.ply'));
  await page.waitForFunction((n) => window.__meshmorph.state.loads > n, loads, { timeout: 60000 });
  await waitIdle(page);
  await nextFrame(page);
  const mesh = await page.evaluate(() => window.__meshmorph.state.mesh);
  check(mesh.name === 'armadillo.ply' && mesh.weldedVertices === 14587, `loaded ${JSON.stringify({ name: mesh.name, v: mesh.weldedVertices })}`);
  check(pixelStats(await canvasPixels(page)).foreground > 0.04, 'armadillo not visible');
  check((await page.textContent('#info')).includes('armadillo.ply'), 'info panel not updated');
  await shot(page, '02-picker-armadillo');
});

it('a .gltf with its .bin and texture opens through the picker (multi-file)', async ({ page }) => {
  const loads = await loadCount(page);
  const dir = path.join(repoDir, 'data/anim/Fox/glTF');
  await page.setInputFiles('#file', ['Fox.gltf', 'Fox.bin', 'Texture.png'].map((f) => path.join(dir, f)));
  await page.waitForFunction((n) => window.__meshmorph.state.loads > n || window.__meshmorph.state.error, loads, { timeout: 60000 });
  await waitIdle(page);
  const { mesh, error } = await page.evaluate(() => ({ mesh: window.__meshmorph.state.mesh, error: window.__meshmorph.state.error }));
  check(mesh.name === 'Fox.gltf', `expected Fox.gltf, got ${mesh.name} (error ${JSON.stringify(error)})`);
  await nextFrame(page);
  check(pixelStats(await canvasPixels(page)).foreground > 0.02, 'fox not visible');
  await shot(page, '03-picker-fox-gltf');
});

it('malformed files show their error and the page keeps working', async ({ page }) => {
  const before = await page.evaluate(() => window.__meshmorph.state.mesh.name);
  const garbage = Buffer.alloc(3000, 0);
  garbage.write('glTF', 0);
  garbage.writeUInt32LE(2, 4);
  garbage.writeUInt32LE(3000, 8);
  garbage.writeUInt32LE(500, 12);
  garbage.write('JSON', 16);
  garbage.write('{"asset": {"version": "2.0"}, "meshes": [ this is not json', 20);
  const cases = [
    { name: 'broken.glb', mimeType: 'model/gltf-binary', buffer: garbage },
    { name: 'truncated.ply', mimeType: 'application/octet-stream', buffer: fs.readFileSync(path.join(repoDir, 'data/edit/skull.ply')).subarray(0, 30000) },
    { name: 'notes.txt', mimeType: 'text/plain', buffer: Buffer.from('not a mesh') },
  ];
  const badDir = path.join(repoDir, 'tests/bad');
  if (fs.existsSync(badDir)) {
    for (const f of fs.readdirSync(badDir).filter((n) => /\.(glb|gltf|obj|off|ply)$/i.test(n)).slice(0, 3)) {
      cases.push({ name: f, mimeType: 'application/octet-stream', buffer: fs.readFileSync(path.join(badDir, f)) });
    }
  }
  let i = 0;
  for (const file of cases) {
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.setInputFiles('#file', file);
    await page.waitForFunction(() => window.__meshmorph.state.error !== null, null, { timeout: 30000 });
    await waitIdle(page);
    const shown = await page.textContent('#error');
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(await page.isVisible('#error'), `${file.name}: error banner hidden`);
    check(error.message.length > 10 && shown.includes(error.message), `${file.name}: message not shown (${shown})`);
    check(!/Internal|Crashed/.test(error.code), `${file.name}: not a data error: ${error.code} ${error.message}`);
    if (i++ === 0) await shot(page, '04-malformed-error');
    const after = await page.evaluate(() => window.__meshmorph.state.mesh.name);
    check(after === before, `${file.name}: the current mesh changed to ${after}`);
  }
  await page.click('#error-close');
  check(!(await page.isVisible('#error')), 'error banner cannot be dismissed');
  await pickSample(page, 'skull');
  check(await page.evaluate(() => window.__meshmorph.state.mesh.name === 'skull.ply'), 'the page stopped working after the errors');
});

it('eigenfunction view: colours change with the slider', async ({ page }) => {
  await computeBasis(page, 20);
  await page.waitForFunction(() => window.__meshmorph.state.eigen !== null, null, { timeout: 60000 });
  await waitIdle(page);
  await nextFrame(page);
  const first = await canvasPixels(page);
  const firstStats = pixelStats(first);
  await shot(page, '05-eigenfunction-1');
  check(firstStats.coloured > 0.02, `the mesh is not coloured (${(firstStats.coloured * 100).toFixed(1)}% coloured pixels)`);
  await page.fill('#eig-i', '7');
  await page.dispatchEvent('#eig-i', 'input');
  await nextFrame(page);
  const second = await canvasPixels(page);
  await shot(page, '05-eigenfunction-7');
  const i = await page.evaluate(() => window.__meshmorph.state.eigen.i);
  check(i === 7, `slider did not select φ7 (i = ${i})`);
  const diff = pixelDifference(first, second);
  check(diff > 0.01, `φ1 and φ7 look the same (${(diff * 100).toFixed(2)}% of pixels differ)`);
  const label = await page.textContent('#eig-value');
  check(/λ₇ = [0-9.e+-]+ .*(Spectra|block Lanczos|dense)\)/.test(label), `eigenvalue label names the value and the solver: ${label}`);
  await page.check('#wireframe');
  await nextFrame(page);
  await shot(page, '05-eigenfunction-7-wireframe');
  await page.uncheck('#wireframe');
});

it('export downloads a GLB (magic glTF, passes glTF-Validator)', async ({ page }) => {
  const [download] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#export')]);
  const file = path.join(shotDir, download.suggestedFilename());
  await download.saveAs(file);
  const bytes = fs.readFileSync(file);
  check(download.suggestedFilename() === 'skull.glb', `file name ${download.suggestedFilename()}`);
  check(bytes.subarray(0, 4).toString('latin1') === 'glTF', `magic is ${JSON.stringify(bytes.subarray(0, 4).toString('latin1'))}`);
  check(bytes.readUInt32LE(8) === bytes.length, 'GLB header length differs from the file size');
  const validator = await import('gltf-validator');
  const report = await validator.validateBytes(new Uint8Array(bytes));
  check(report.issues.numErrors === 0, `glTF-Validator: ${report.issues.numErrors} errors: ${JSON.stringify(report.issues.messages.slice(0, 3))}`);
});

it('cancel stops a long computation (shared-memory flag; the worker survives)', async ({ page }) => {
  await pickSample(page, 'armadillo');
  const restarts = await page.evaluate(() => window.__meshmorph.restarts);
  const ms = await cancelLongComputation(page, '06-cancel-cooperative');
  await shot(page, '06-cancel-cooperative-done');
  check(await page.evaluate((n) => window.__meshmorph.restarts === n, restarts), 'the worker was restarted; the cooperative cancel did not stop the op');
  check(ms < 5000, `cancel took ${ms} ms`);
  // The loaded mesh is still there: a small basis computes.
  await computeBasis(page, 10);
  await page.waitForFunction(() => window.__meshmorph.state.eigen?.k === 10, null, { timeout: 60000 });
  await waitIdle(page);
});

it('cancel by terminating the worker: a new worker restores the mesh', async ({ context, baseUrl }) => {
  const page = await context.newPage();
  await page.setViewportSize({ width: 1280, height: 800 });
  await page.goto(`${baseUrl}?cancel=terminate&sample=armadillo`);
  await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1, null, { timeout: 60000 });
  await waitIdle(page);
  check(await page.evaluate(() => window.__meshmorph.cancelMode) === 'terminate', 'cancel mode not forced');
  const ms = await cancelLongComputation(page, '07-cancel-terminate');
  check(await page.evaluate(() => window.__meshmorph.restarts) === 1, 'the worker was not replaced');
  check(ms < 5000, `cancel took ${ms} ms`);
  await computeBasis(page, 10);
  await page.waitForFunction(() => window.__meshmorph.state.eigen?.k === 10 || window.__meshmorph.state.error?.code !== 'Cancelled', null, { timeout: 60000 });
  const { eigen, error } = await page.evaluate(() => ({ eigen: window.__meshmorph.state.eigen, error: window.__meshmorph.state.error }));
  check(eigen?.k === 10, `after the restart the mesh was not restored: ${JSON.stringify(error)}`);
  await nextFrame(page);
  await shot(page, '07-cancel-terminate-after');
  check(pixelStats(await canvasPixels(page)).coloured > 0.02, 'no colours after the restart');
  await page.close();
});

it('drag and drop of a file onto the view opens it', async ({ page }) => {
  const loads = await loadCount(page);
  const bytes = fs.readFileSync(path.join(repoDir, 'data/edit/hand_lowres.ply')).toString('base64');
  const dataTransfer = await page.evaluateHandle((b64) => {
    const raw = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const dt = new DataTransfer();
    dt.items.add(new File([raw], 'hand_lowres.ply', { type: 'application/octet-stream' }));
    return dt;
  }, bytes);
  await page.dispatchEvent('#viewport', 'dragenter', { dataTransfer });
  check(await page.isVisible('#drop-overlay'), 'no drop overlay while dragging');
  await page.dispatchEvent('#viewport', 'drop', { dataTransfer });
  await page.waitForFunction((n) => window.__meshmorph.state.loads > n, loads, { timeout: 30000 });
  await waitIdle(page);
  await nextFrame(page);
  check(await page.evaluate(() => window.__meshmorph.state.mesh.name === 'hand_lowres.ply'), 'dropped file not loaded');
  check(!(await page.isVisible('#drop-overlay')), 'drop overlay stays visible');
  await shot(page, '08-dropped-hand');
});

it('gallery: every sample loads and renders', async ({ page }) => {
  const ids = await page.evaluate(() => [...document.querySelectorAll('#sample option')].map((o) => o.value).filter(Boolean));
  const failed = [];
  for (const id of ids) {
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    const loads = await loadCount(page);
    await page.selectOption('#sample', id);
    await page.waitForFunction((n) => window.__meshmorph.state.loads > n || window.__meshmorph.state.error, loads, { timeout: 60000 });
    await waitIdle(page);
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    if (error) { failed.push(`${id}: ${error.code} ${error.message}`); continue; }
    await nextFrame(page);
    const stats = pixelStats(await canvasPixels(page));
    await shot(page, `09-gallery-${id}`);
    if (stats.foreground < 0.02) failed.push(`${id}: blank canvas`);
  }
  check(failed.length === 0, failed.join('; '));
});

// Pixels of the Fox's texture: clearly orange (red well above green, green well above blue).
function orangeShare({ data }) {
  let orange = 0;
  for (let i = 0; i < data.length; i += 4) {
    const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
    if (r > 120 && r - g > 30 && g - b > 25) orange += 1;
  }
  return orange / (data.length / 4);
}

it('glTF materials: the Fox shows its own texture; the toggle gives the analysis material', async ({ page }) => {
  await pickSample(page, 'fox');
  await page.waitForFunction(() => window.__meshmorph.state.materials && !window.__meshmorph.state.materials.pending, null, { timeout: 30000 });
  const materials = await page.evaluate(() => ({ ...window.__meshmorph.state.materials }));
  check(materials.available && materials.textured && materials.shown === 'document', `Fox materials: ${JSON.stringify(materials)}`);
  // The texture is an image: wait for it to be decoded and uploaded (a few frames).
  let textured = 0;
  for (let i = 0; i < 20 && textured < 0.03; ++i) {
    await nextFrame(page);
    textured = orangeShare(await canvasPixels(page));
  }
  await shot(page, '09-materials-fox-textured');
  check(textured > 0.03, `only ${(textured * 100).toFixed(1)}% of the view shows the Fox's orange texture`);
  await page.uncheck('#materials');
  await nextFrame(page);
  const plain = orangeShare(await canvasPixels(page));
  await shot(page, '09-materials-fox-analysis');
  check(await page.evaluate(() => window.__meshmorph.state.materials.shown) === 'analysis' && plain < 0.2 * textured,
    `the analysis material still shows the texture (${(plain * 100).toFixed(1)}% orange)`);
  await page.check('#materials');
  // Eigenfunction colours use the analysis material whatever the toggle says.
  await computeBasis(page, 10);
  await page.waitForFunction(() => window.__meshmorph.state.eigen?.k === 10, null, { timeout: 60000 });
  await waitIdle(page);
  check(await page.evaluate(() => window.__meshmorph.state.materials.shown) === 'analysis', 'colours are not drawn with the analysis material');
  await page.click('#eig-clear').catch(() => {});
  // A PLY has no document materials: the toggle is off-limits and says why.
  await pickSample(page, 'hand');
  check(await page.isDisabled('#materials'), 'the Materials toggle is enabled for a PLY');
});

// Canvas pixels that differ from the background: bounding box in 0..1 of the view.
function foregroundBox({ w, h, data }) {
  let x0 = w;
  let y0 = h;
  let x1 = -1;
  let y1 = -1;
  for (let y = 0; y < h; ++y) {
    for (let x = 0; x < w; ++x) {
      const i = 4 * (y * w + x);
      if (Math.abs(data[i] - background[0]) + Math.abs(data[i + 1] - background[1]) + Math.abs(data[i + 2] - background[2]) > 30) {
        x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
      }
    }
  }
  return { x0: x0 / w, x1: (x1 + 1) / w, y0: y0 / h, y1: (y1 + 1) / h };
}

it('the camera reframes when the window changes size', async ({ page }) => {
  await pickSample(page, 'armadillo');
  const sizes = [{ width: 760, height: 800 }, { width: 1280, height: 520 }, { width: 1280, height: 800 }];
  for (const size of sizes) {
    await page.setViewportSize(size);
    await page.waitForFunction((w) => Math.abs(document.getElementById('view').clientWidth - w) < 2, size.width - 350, { timeout: 5000 }).catch(() => {});
    await nextFrame(page);
    await nextFrame(page);
    const box = foregroundBox(await canvasPixels(page));
    await shot(page, `09-resize-${size.width}x${size.height}`);
    const inside = box.x0 > 0.005 && box.y0 > 0.005 && box.x1 < 0.995 && box.y1 < 0.995;
    const fills = Math.max(box.x1 - box.x0, box.y1 - box.y0) > 0.6;
    check(inside && fills, `${size.width}×${size.height}: the mesh spans x ${box.x0.toFixed(2)}–${box.x1.toFixed(2)}, y ${box.y0.toFixed(2)}–${box.y1.toFixed(2)} of the view`);
  }
});

it('vertex picking: the real mouse over the mesh shows the vertex, a click pins it', async ({ page }) => {
  await pickSample(page, 'armadillo');
  const box = await page.locator('#view').boundingBox();
  // The mesh is framed in the middle of the view: try points around the centre until the
  // pointer is over the surface.
  const offsets = [[0, 0], [0, 0.08], [0, -0.08], [0.06, 0], [-0.06, 0], [0.03, 0.2], [-0.03, -0.2]];
  let pick = null;
  let at = null;
  for (const [dx, dy] of offsets) {
    at = { x: box.x + box.width * (0.5 + dx), y: box.y + box.height * (0.5 + dy) };
    await page.mouse.move(at.x, at.y, { steps: 5 });
    pick = await page.waitForFunction(() => window.__meshmorph.state.pick, null, { timeout: 3000 })
      .then((handle) => handle.jsonValue(), () => null);
    if (pick) break;
  }
  check(pick, 'moving the mouse over the middle of the view picked no vertex');
  const mesh = await page.evaluate(() => {
    const { state } = window.__meshmorph;
    return { raw: state.mesh.rawVertices, welded: state.mesh.weldedVertices, mapped: state.mesh.toWelded[state.pick.vertex] };
  });
  check(Number.isInteger(pick.vertex) && pick.vertex >= 0 && pick.vertex < mesh.raw, `vertex ${pick.vertex} of ${mesh.raw}`);
  check(pick.welded === mesh.mapped && pick.welded < mesh.welded, `welded index ${pick.welded}, toWelded says ${mesh.mapped}`);
  check(pick.point.length === 3 && pick.point.every(Number.isFinite) && pick.distance > 0, `pick ${JSON.stringify(pick)}`);
  const gap = Math.hypot(...pick.point.map((v, i) => v - pick.hit[i]));
  check(gap < 0.05 * pick.distance, `the picked vertex is ${gap} from the hit point (ray length ${pick.distance})`);
  const hoverText = await page.textContent('#pick-hover');
  check(new RegExp(`vertex #${pick.welded} \\(-?[0-9.]+, -?[0-9.]+, -?[0-9.]+\\)`).test(hoverText), `panel shows: ${hoverText}`);
  await nextFrame(page);
  await shot(page, '10-pick-hover');

  await page.mouse.down();
  await page.mouse.up();
  await page.waitForFunction(() => window.__meshmorph.state.pinned, null, { timeout: 3000 });
  const pinned = await page.evaluate(() => window.__meshmorph.state.pinned);
  check(pinned.vertex === pick.vertex, `clicked at the hovered vertex ${pick.vertex}, pinned ${pinned.vertex}`);
  check((await page.textContent('#pick-pinned')).includes(`pinned: vertex #${pick.welded} (`), 'pinned vertex not shown in the panel');

  // Off the mesh (a corner of the view): the hover pick goes, the pinned one stays.
  await page.mouse.move(box.x + 8, box.y + box.height - 8, { steps: 5 });
  await page.waitForFunction(() => window.__meshmorph.state.pick === null, null, { timeout: 3000 });
  check(await page.isVisible('#pick-pinned'), 'the pinned vertex disappeared when the pointer left the mesh');
  await nextFrame(page);
  await shot(page, '10-pick-pinned');
});

// ---- the Edit job

// The first of the raw vertices, ordered by `key` (a function body over x, y, z, evaluated in the
// page), that the camera sees: its index and client position.
async function visibleVertex(page, key) {
  return page.evaluate((keySource) => {
    const score = new Function('x', 'y', 'z', `return ${keySource};`);
    const p = window.__meshmorph.hooks.editPositions().raw;
    const order = [...Array(p.length / 3).keys()].sort((a, b) => score(p[3 * b], p[3 * b + 1], p[3 * b + 2]) - score(p[3 * a], p[3 * a + 1], p[3 * a + 2]));
    for (const v of order.slice(0, 400)) {
      const s = window.__meshmorph.vertexOnScreen(v);
      if (s.visible) return { vertex: v, ...s };
    }
    return null;
  }, key);
}

// A short brush stroke with the real mouse around a client position.
async function stroke(page, { x, y }) {
  await page.mouse.move(x, y, { steps: 3 });
  await page.mouse.down();
  for (const [dx, dy] of [[6, 0], [6, 6], [0, 6], [-6, 6], [-6, 0], [0, 0]]) await page.mouse.move(x + dx, y + dy, { steps: 2 });
  await page.mouse.up();
}

const bboxDiagonal = (p) => {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < p.length; i += 3) for (let k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], p[i + k]); hi[k] = Math.max(hi[k], p[i + k]); }
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
};

// x ↦ M x for a column-major 4x4 M.
const transformPoint = (m, x, y, z) => [m[0] * x + m[4] * y + m[8] * z + m[12], m[1] * x + m[5] * y + m[9] * z + m[13], m[2] * x + m[6] * y + m[10] * z + m[14]];

const editState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.edit)));

async function waitFinalized(page, n) {
  await page.waitForFunction((k) => window.__meshmorph.state.edit.finalized >= k || window.__meshmorph.state.error, n, { timeout: 30000 });
  await waitIdle(page);
  const error = await page.evaluate(() => window.__meshmorph.state.error);
  check(!error, `edit error: ${JSON.stringify(error)}`);
}

// Runs `meshmorph edit` on a spec the page saved and compares its vertices with the page's
// (raw layout, as displayed).
function cliMatchesPage(meshFile, specFile, pagePositions, diagonal, label) {
  check(fs.existsSync(cliPath), `the CLI is missing: ${cliPath} (set MM_CLI)`);
  const out = path.join(shotDir, `${path.basename(specFile, '.json')}-cli.ply`);
  const run = spawnSync(cliPath, ['edit', meshFile, '--spec', specFile, '--out', out, '--quiet'], { encoding: 'utf8', timeout: 120000 });
  check(run.status === 0, `meshmorph edit failed (${run.status}): ${run.stderr}`);
  const cli = readPlyVertices(fs.readFileSync(out));
  check(cli.length === pagePositions.length, `the CLI wrote ${cli.length / 3} vertices, the page shows ${pagePositions.length / 3}`);
  let error = 0;
  const p = pagePositions;
  for (let i = 0; i < cli.length; i += 3) error = Math.max(error, Math.hypot(cli[i] - p[i], cli[i + 1] - p[i + 1], cli[i + 2] - p[i + 2]));
  console.log(`     page vs CLI (${label}): max vertex difference ${(error / diagonal).toExponential(2)}·diag`);
  check(error <= 1e-6 * diagonal, `page and CLI (${label}) differ by ${error / diagonal}·diag`);
}

it('edit: brush two handles and a fixed part, drag the gizmo, finalize; the saved spec gives the CLI the same mesh', async ({ page, pageErrors, browser }) => {
  const errorsBefore = pageErrors.length;
  const restFile = path.join(repoDir, 'data/edit/armadillo.ply');
  const rest = readPlyVertices(fs.readFileSync(restFile));
  const diagonal = bboxDiagonal(rest);
  await pickSample(page, 'armadillo');
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.click('#jobs button[data-job="edit"]');
  await page.waitForSelector('#edit-select', { state: 'visible' });
  let edit = await editState(page);
  check(edit.step === 0 && edit.handle === 0 && !edit.session, `initial edit state ${JSON.stringify(edit)}`);
  check(/paint/i.test(await page.textContent('.steps li.current')), 'step 1 does not name the next action');

  // Options from the schema (lil-gui): a collapsible panel, closed at first, one controller
  // per option at its default, a help line under each and as a tooltip; one non-default option
  // goes into the spec (and so to the CLI).
  const optionsTitle = 'section.edit .lil-gui.options > .lil-title';
  check(!(await page.isVisible('#opt-coherence_rings')), 'the options panel is not closed at first');
  await page.click(optionsTitle);
  await page.waitForSelector('#opt-coherence_rings', { state: 'visible' });
  const optionCount = await page.locator('section.edit .option').count();
  check(optionCount >= 8, `only ${optionCount} options shown`);
  check((await page.inputValue('#opt-coherence_rings')) === '2', `coherence_rings starts at ${await page.inputValue('#opt-coherence_rings')}, not the paper's 2`);
  const help = await page.evaluate(() => document.getElementById('opt-coherence_rings').closest('.option').nextElementSibling.textContent);
  check(/Eq\. 6/.test(help) && /1 … 3/.test(help), `coherence_rings help line: ${help}`);
  check(((await page.locator('section.edit .option').first().getAttribute('title')) || '').length > 10, 'options have no help tooltip');
  check(await page.locator('section.edit select#opt-method option').count() >= 2, 'the method (implicit / naive baseline) is not a choice');
  await page.fill('#opt-finalize_refinements', '2');
  await shot(page, '11-edit-0-options');
  await page.click(optionsTitle);

  // 1: the handle — the brush on the outermost visible vertex of the hand on the right (real
  // mouse), grown by two rings.
  await page.click('#edit-brush');
  const hand = await visibleVertex(page, 'x');
  check(hand, 'no visible vertex on the right of the mesh');
  await stroke(page, hand);
  edit = await editState(page);
  check(edit.handle > 0, 'the brush stroke selected no handle vertex');
  const painted = edit.handle;
  await page.click('#edit-grow');
  await page.click('#edit-grow');
  edit = await editState(page);
  check(edit.handle > painted && edit.step === 1, `grow: ${painted} → ${edit.handle} (step ${edit.step})`);
  // A second handle on the other hand: it stays where it is while the first one moves.
  await page.click('#edit-new-handle');
  const otherHand = await visibleVertex(page, '-x');
  check(otherHand, 'no visible vertex on the left of the mesh');
  await page.mouse.move(otherHand.x, otherHand.y, { steps: 3 });
  // The Merge job has a brush cursor of its own (hidden here): look for the one that shows.
  check(await page.evaluate(() => [...document.querySelectorAll('.brush-cursor')].some((e) => !e.hidden && e.getBoundingClientRect().width > 0)), 'no brush cursor over the mesh');
  await shot(page, '11-edit-1-brush');
  await stroke(page, otherHand);
  await page.click('#edit-grow');
  edit = await editState(page);
  check(edit.handles.length === 2 && edit.handles[1] > 0 && edit.active === 1, `second handle: ${JSON.stringify(edit.handles)}`);
  await page.selectOption('#edit-handle', '0');
  // 2: the fixed part — the lowest visible vertices of both feet, painted holding B (brush off).
  await page.click('#edit-brush');
  await page.check('input[name="edit-target"][value="fixed"]');
  for (const key of ['-y - 0.5 * x', '-y + 0.5 * x']) {
    const foot = await visibleVertex(page, key);
    check(foot, `no visible vertex for ${key}`);
    await page.keyboard.down('b');
    await stroke(page, foot);
    await page.keyboard.up('b');
  }
  await page.click('#edit-grow');
  await page.click('#edit-grow');
  edit = await editState(page);
  check(edit.fixed > 0, 'the brush selected no fixed vertex');
  await nextFrame(page);
  await shot(page, '11-edit-1-selection');
  check(pixelStats(await canvasPixels(page)).coloured > 0.001, 'the selection is not coloured');

  // 3: start, then drag the gizmo's Y arrow with the real mouse at about 60 moves a second.
  await page.click('#edit-start');
  await page.waitForFunction(() => window.__meshmorph.state.edit.session || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  edit = await editState(page);
  check(edit.session && edit.step === 2, `no session: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  check(edit.spec.options?.finalize_refinements === 2, `options not in the spec: ${JSON.stringify(edit.spec.options)}`);
  await nextFrame(page);
  await shot(page, '11-edit-2-gizmo');
  const arrow = await page.evaluate(() => window.__meshmorph.hooks.editGizmoHandle('Y'));
  check(arrow && Number.isFinite(arrow.x), 'no gizmo on screen');
  await page.mouse.move(arrow.x, arrow.y, { steps: 2 });
  await page.mouse.down();
  const dragStarted = Date.now();
  const dragFrom = await page.evaluate(() => performance.now());
  for (let i = 1; i <= 40; ++i) {
    await page.mouse.move(arrow.x + i, arrow.y - 3 * i);
    await page.waitForTimeout(16);
  }
  const dragMs = Date.now() - dragStarted;
  await page.mouse.up();
  const dragTo = await page.evaluate(() => performance.now());
  await shot(page, '11-edit-3-dragging');
  await waitFinalized(page, 1);
  edit = await editState(page);
  const seconds = (edit.drags.last - edit.drags.first) / 1000;
  const frameMs = await page.evaluate(async () => {
    const started = performance.now();
    for (let i = 0; i < 5; ++i) await window.__meshmorph.nextFrame();
    return (performance.now() - started) / 5;
  });
  console.log(`     drag: 40 mouse moves in ${dragMs} ms → ${edit.drags.sent} editDrag requests, ${edit.drags.answered} answered, `
    + `${(edit.drags.answered / seconds).toFixed(1)} per second; mean worker round trip ${(edit.drags.roundTripMs / edit.drags.answered).toFixed(1)} ms, `
    + `geometry update ${(edit.drags.applyMs / edit.drags.answered).toFixed(1)} ms, a rendered frame ${frameMs.toFixed(0)} ms`);
  const longest = await longestTask(page, dragFrom, dragTo);
  if (longest >= 0) {
    const all = await page.evaluate(({ a, b }) => window.__longTasks.filter((t) => t.start < b && t.start + t.duration > a).map((t) => `${(t.start - a).toFixed(0)}+${t.duration.toFixed(0)}`), { a: dragFrom, b: dragTo });
    if (longest >= longTaskTargetMs) {
      const frames = await page.evaluate(({ a, b }) => (window.__longFrames || []).filter((f) => f.start < b && f.start + f.duration > a && f.scripts.length), { a: dragFrom, b: dragTo });
      for (const f of frames) console.log(`     slow frame at ${(f.start - dragFrom).toFixed(0)} ms: ${f.duration.toFixed(0)} ms (blocking ${f.blocking.toFixed(0)}, render ${f.render.toFixed(0)}): ${f.scripts.join(' | ')}`);
    }
    console.log(`     longest main-thread task during the drag: ${longest.toFixed(0)} ms (long-task observer; target < ${longTaskTargetMs} ms; tasks at ms+duration: ${all.join(' ') || 'none'} of ${(dragTo - dragFrom).toFixed(0)} ms)`);
    record(browser, 'longestDragTaskMs', longest.toFixed(0));
    // Wall-clock: on a machine busy with other work (load average above the core count) a
    // task stretches, so the target is asserted only when the machine is not overloaded.
    const load = os.loadavg()[0];
    if (load <= os.cpus().length) check(longest < longTaskTargetMs, `a main-thread task of ${longest.toFixed(0)} ms during the drag`);
    else if (longest >= longTaskTargetMs) console.log(`     (not asserted: load average ${load.toFixed(1)} on ${os.cpus().length} cores)`);
  }
  record(browser, 'dragRate', `${(edit.drags.answered / ((edit.drags.last - edit.drags.first) / 1000)).toFixed(1)} editDrag answers/s (armadillo, 14587 vertices)`);
  check(edit.drags.sent >= 5 && edit.drags.answered === edit.drags.sent, `drag requests ${JSON.stringify(edit.drags)}`);
  check(edit.step === 3, `step after the drag: ${edit.step}`);
  const m = edit.matrices[0];
  const lift = Math.hypot(m[12], m[13], m[14]);
  check(edit.matrices.length === 2 && edit.matrices[1].every((v, i) => v === [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1][i]), `the second handle moved: ${JSON.stringify(edit.matrices)}`);
  check(m[13] > 0.05 * diagonal, `the gizmo moved the handle by ${JSON.stringify(m.slice(12, 15))} (diagonal ${diagonal})`);
  await nextFrame(page);
  await shot(page, '11-edit-4-finalized');

  // The mesh moved: handle vertices at M·rest, fixed vertices at rest.
  const { raw, welded } = await page.evaluate(() => window.__meshmorph.hooks.editPositions());
  const toWelded = await page.evaluate(() => Array.from(window.__meshmorph.state.mesh.toWelded));
  check(welded && welded.length === rest.length, 'no welded positions after finalize');
  let handleError = 0;
  edit.spec.handles.forEach(({ select }, h) => {
    for (const w of select) {
      const target = transformPoint(edit.matrices[h], rest[3 * w], rest[3 * w + 1], rest[3 * w + 2]);
      handleError = Math.max(handleError, Math.hypot(...target.map((t, k) => t - welded[3 * w + k])));
    }
  });
  check(handleError < 1e-5 * diagonal, `handle vertices are ${handleError / diagonal}·diag from their targets`);
  let fixedError = 0;
  for (const w of edit.spec.fixed) fixedError = Math.max(fixedError, Math.hypot(...[0, 1, 2].map((k) => rest[3 * w + k] - welded[3 * w + k])));
  check(fixedError < 1e-5 * diagonal, `fixed vertices moved by ${fixedError / diagonal}·diag`);
  let moved = 0;
  for (let i = 0; i < rest.length; i += 3) moved = Math.max(moved, Math.hypot(rest[i] - raw[i], rest[i + 1] - raw[i + 1], rest[i + 2] - raw[i + 2]));
  check(moved > 0.5 * lift, `largest displacement ${moved}, handle lifted by ${lift}`);
  for (let r = 0; r < toWelded.length; r += 97) {
    const w = toWelded[r];
    check([0, 1, 2].every((k) => raw[3 * r + k] === welded[3 * w + k]), `displayed vertex ${r} differs from welded ${w}`);
  }

  // 4: save the spec; the CLI on it gives the same vertices.
  const [specDownload] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#edit-save')]);
  const specFile = path.join(shotDir, specDownload.suggestedFilename());
  await specDownload.saveAs(specFile);
  const spec = JSON.parse(fs.readFileSync(specFile, 'utf8'));
  check(JSON.stringify(spec.handles.map((h) => h.matrix)) === JSON.stringify(edit.matrices), 'the saved matrices are not the ones the page sent');
  check(JSON.stringify({ ...spec, handles: spec.handles.map((h) => ({ select: h.select })) }) === JSON.stringify(edit.spec), 'the saved spec differs from the one the page created the session with');
  cliMatchesPage(restFile, specFile, raw, diagonal, 'translate');

  // The worker dies with the session open: the page prepares the same edit in the new worker and
  // brings its steps back — the same mesh, the same matrices, and undo below still goes to rest.
  const recoveries = await page.evaluate(() => window.__meshmorph.state.recoveries || 0);
  await page.evaluate(() => { window.__meshmorph.client.run('debugCrash').promise.catch(() => {}); });
  await page.waitForFunction((n) => (window.__meshmorph.state.recoveries || 0) > n, recoveries, { timeout: 60000 });
  await page.waitForFunction(() => window.__meshmorph.state.edit.restored >= 1 || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  const restoredEdit = await page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.edit)));
  const restoredRaw = (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw;
  let restoreError = 0;
  for (let i = 0; i < raw.length; ++i) restoreError = Math.max(restoreError, Math.abs(restoredRaw[i] - raw[i]));
  console.log(`     edit session restored after a worker crash: ${(restoreError / diagonal).toExponential(2)}·diag from the mesh before`);
  check(restoredEdit.session && restoredEdit.restored === 1 && JSON.stringify(restoredEdit.matrices) === JSON.stringify(edit.matrices),
    `the edit session after the crash: ${JSON.stringify({ session: restoredEdit.session, restored: restoredEdit.restored, matrices: restoredEdit.matrices })}`);
  check(restoreError <= 1e-9 * diagonal, `the restored session shows another mesh (${restoreError / diagonal}·diag)`);
  check(restoredEdit.finalized === 1, `finalized ${restoredEdit.finalized} times after the restore`);

  // Undo goes back to the rest shape, redo to the edit.
  await page.click('#edit-undo');
  await waitFinalized(page, 2);
  const undone = (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw;
  let undoError = 0;
  for (let i = 0; i < rest.length; ++i) undoError = Math.max(undoError, Math.abs(undone[i] - rest[i]));
  check(undoError < 1e-5 * diagonal, `undo left the mesh ${undoError / diagonal}·diag from rest`);
  await page.click('#edit-redo');
  await waitFinalized(page, 3);

  // Scale mode (key R): stretch handle 1 along its Y axis with the real mouse; the saved spec
  // (a matrix with a linear part now) again gives the CLI the page's vertices.
  await page.keyboard.press('r');
  check(await page.isChecked('input[name="edit-mode"][value="scale"]'), 'the R key did not select the scale gizmo');
  await nextFrame(page);
  const scaleY = await page.evaluate(() => window.__meshmorph.hooks.editGizmoHandle('Y'));
  check(scaleY && Number.isFinite(scaleY.x), 'no scale gizmo on screen');
  await page.mouse.move(scaleY.x, scaleY.y, { steps: 2 });
  await page.mouse.down();
  for (let i = 1; i <= 10; ++i) await page.mouse.move(scaleY.x, scaleY.y - 3 * i);
  await page.mouse.up();
  await waitFinalized(page, 4);
  edit = await editState(page);
  const scaled = edit.matrices[0];
  const yScale = Math.hypot(scaled[4], scaled[5], scaled[6]);
  check(Math.abs(yScale - 1) > 0.05 && Math.abs(Math.hypot(scaled[0], scaled[1], scaled[2]) - 1) < 1e-9, `scale drag gave ${JSON.stringify(scaled.slice(0, 12))}`);
  await nextFrame(page);
  await shot(page, '11-edit-4-scaled');
  const [scaledDownload] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#edit-save')]);
  const scaledSpec = path.join(shotDir, 'armadillo-scaled.edit.json');
  await scaledDownload.saveAs(scaledSpec);
  cliMatchesPage(restFile, scaledSpec, (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw, diagonal, 'scale');
  await page.keyboard.press('w');
  await page.click('#edit-undo');
  await waitFinalized(page, 5);

  // Export the edited mesh as GLB.
  const [glb] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#edit-export')]);
  const glbFile = path.join(shotDir, glb.suggestedFilename());
  await glb.saveAs(glbFile);
  const bytes = fs.readFileSync(glbFile);
  check(bytes.subarray(0, 4).toString('latin1') === 'glTF' && bytes.readUInt32LE(8) === bytes.length, `bad GLB ${glb.suggestedFilename()}`);
  const report = await (await import('gltf-validator')).validateBytes(new Uint8Array(bytes));
  check(report.issues.numErrors === 0, `edited GLB: glTF-Validator: ${JSON.stringify(report.issues.messages.slice(0, 3))}`);

  // Loading the saved spec starts a session and gives the same shape again.
  await page.click('#edit-stop');
  await waitIdle(page);
  await page.setInputFiles('#edit-load', specFile);
  await page.waitForFunction(() => window.__meshmorph.state.edit.session && window.__meshmorph.state.edit.finalized >= 1 || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), 'loading the spec failed');
  const reloaded = (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw;
  let reloadError = 0;
  for (let i = 0; i < raw.length; ++i) reloadError = Math.max(reloadError, Math.abs(reloaded[i] - raw[i]));
  check(reloadError <= 1e-6 * diagonal, `the loaded spec gives a shape ${reloadError / diagonal}·diag away`);
  await nextFrame(page);
  await shot(page, '11-edit-5-loaded-spec');
  // Other jobs show the loaded mesh; the edit comes back with the Edit tab.
  await page.click('#jobs button[data-job="mesh"]');
  const inMesh = (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw;
  check(inMesh.every((v, i) => v === Math.fround(rest[i])), 'the Mesh job shows the edited mesh');
  await page.click('#jobs button[data-job="edit"]');
  const back = (await page.evaluate(() => window.__meshmorph.hooks.editPositions())).raw;
  check(back.every((v, i) => v === reloaded[i]), 'the edit is not shown again in the Edit tab');
  check(pageErrors.length === errorsBefore, `uncaught page errors: ${pageErrors.slice(errorsBefore).join(' | ')}`);
  await page.click('#edit-stop');
  await page.click('#jobs button[data-job="mesh"]');
});

// ---- the Transfer job

const transferState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.transfer)));

// Up to `count` raw vertices of a side of the Transfer view, ordered by `key` (as in
// visibleVertex), that the camera sees: index and client position of each.
async function visibleOnSide(page, side, key, count = 8) {
  return page.evaluate(({ side: s, keySource, n }) => {
    const score = new Function('x', 'y', 'z', `return ${keySource};`);
    const p = window.__meshmorph.hooks.transferShown(s);
    const order = [...Array(p.length / 3).keys()].sort((a, b) => score(p[3 * b], p[3 * b + 1], p[3 * b + 2]) - score(p[3 * a], p[3 * a + 1], p[3 * a + 2]));
    const out = [];
    for (const v of order.slice(0, 600)) {
      const at = window.__meshmorph.hooks.transferVertexOnScreen(s, v);
      if (at.visible) out.push({ vertex: v, ...at });
      if (out.length === n) break;
    }
    return out;
  }, { side, keySource: key, n: count });
}

// A click with the real mouse at a vertex of a side: the first candidate where the hover pick
// reports that side (a vertex on the silhouette can let the ray miss). `done(arg)` runs in the
// page and says the click took effect; `picked(transfer state)` is the vertex the page chose,
// checked to be under the pointer (within 3 px). `what` names the effect in errors.
async function clickOnSide(page, side, candidates, { done, arg, picked, what }) {
  for (const target of candidates) {
    await page.mouse.move(target.x, target.y, { steps: 4 });
    const hovered = await page.waitForFunction((s) => document.getElementById('tr-hover').textContent.startsWith(s), side, { timeout: 1500 })
      .then(() => true, () => false);
    if (!hovered) continue;
    await page.mouse.down();
    await page.mouse.up();
    await page.waitForFunction(done, arg, { timeout: 3000 })
      .catch(() => { throw new Error(`${side}: the click at vertex ${target.vertex} ${what}`); });
    const vertex = picked(await transferState(page));
    const at = await page.evaluate(({ s, v }) => window.__meshmorph.hooks.transferVertexOnScreen(s, v), { s: side, v: vertex });
    check(Math.hypot(at.x - target.x, at.y - target.y) <= 3, `${side}: clicked at vertex ${target.vertex} (${target.x.toFixed(1)}, ${target.y.toFixed(1)}), picked ${vertex} at (${at.x.toFixed(1)}, ${at.y.toFixed(1)})`);
    return vertex;
  }
  throw new Error(`${side}: no hover pick at any of the vertices ${candidates.map((c) => c.vertex).join(', ')}`);
}

// A new landmark half: returns the pending half or the completed pair's vertex on `side`.
async function clickLandmark(page, side, candidates) {
  const before = await transferState(page);
  return clickOnSide(page, side, candidates, {
    done: (n) => {
      const t = window.__meshmorph.state.transfer;
      return t.pairs.length * 2 + (t.pending ? 1 : 0) > n;
    },
    arg: before.pairs.length * 2 + (before.pending ? 1 : 0),
    picked: (t) => (t.pending ? t.pending.vertex : t.pairs[t.pairs.length - 1][side === 'reference' ? 0 : 1]),
    what: 'added no landmark',
  });
}

// With pair `index` selected, a click on `side` moves that end of the pair; returns its new vertex.
async function moveLandmark(page, side, index, candidates) {
  const k = side === 'reference' ? 0 : 1;
  return clickOnSide(page, side, candidates, {
    done: ({ i, c, b }) => window.__meshmorph.state.transfer.pairs[i][c] !== b,
    arg: { i: index, c: k, b: (await transferState(page)).pairs[index][k] },
    picked: (t) => t.pairs[index][k],
    what: `did not move pair ${index + 1}`,
  });
}

const meanDistance = (a, b) => {
  let sum = 0;
  for (let i = 0; i < a.length; i += 3) sum += Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]);
  return sum / (a.length / 3);
};

it('transfer: the cat pair side by side, run and compare; landmark pairs clicked with the real mouse, saved as JSON', async ({ page, pageErrors, browser }) => {
  const errorsBefore = pageErrors.length;
  const reference = readPlyVertices(fs.readFileSync(path.join(repoDir, 'data/pose/cat-07.ply')));
  const source = readPlyVertices(fs.readFileSync(path.join(repoDir, 'data/pose/cat-reference.ply')));
  await loadCount(page);
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.click('#jobs button[data-job="transfer"]');
  await page.waitForSelector('#tr-steps', { state: 'visible' });
  let t = await transferState(page);
  check(t.step === 0 && !t.reference, `initial transfer state ${JSON.stringify(t)}`);

  // A file dropped on the view while the reference is loading is refused with a message: it
  // opens neither in the Mesh job nor in the Transfer job.
  const meshBefore = await page.evaluate(() => ({ loads: window.__meshmorph.state.loads, name: window.__meshmorph.state.mesh.name }));
  const handFile = path.join(repoDir, 'data/edit/hand_lowres.ply');
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.evaluate(async ({ b64 }) => {
    const select = document.getElementById('tr-reference-sample');
    select.value = 'cat-07';
    select.dispatchEvent(new Event('change'));
    window.__dropFile(b64, 'hand_lowres.ply', 0.25);
  }, { b64: fs.readFileSync(handFile).toString('base64') });
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference || window.__meshmorph.state.transfer.loading === null && window.__meshmorph.state.error?.code !== 'Busy', null, { timeout: 30000 });
  await waitIdle(page);
  let dropped = await page.evaluate(() => ({ loads: window.__meshmorph.state.loads, name: window.__meshmorph.state.mesh.name, error: window.__meshmorph.state.error, reference: window.__meshmorph.state.transfer.reference?.name }));
  check(dropped.loads === meshBefore.loads && dropped.name === meshBefore.name, `the drop during the Transfer load opened ${dropped.name} in the Mesh job`);
  check(dropped.error?.code === 'Busy' && dropped.reference === 'cat-07.ply', `drop while loading: ${JSON.stringify(dropped)}`);
  check(/still loading/.test(await page.textContent('#toast')) && await page.isVisible('#toast'), 'the refused drop is not explained on the view');
  await shot(page, '12-transfer-0-drop-refused');
  // Dropped when idle on the right half, it opens as the source (still not in the Mesh job).
  await page.evaluate(({ b64 }) => window.__dropFile(b64, 'hand_lowres.ply', 0.75), { b64: fs.readFileSync(handFile).toString('base64') });
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  dropped = await page.evaluate(() => ({ loads: window.__meshmorph.state.loads, source: window.__meshmorph.state.transfer.source?.name }));
  check(dropped.source === 'hand_lowres.ply' && dropped.loads === meshBefore.loads, `drop on the right half: ${JSON.stringify(dropped)}`);
  await page.evaluate(() => { window.__meshmorph.state.error = null; });

  // 1, 2: the reference (cat, pose 07) and the source (the cat at rest): same connectivity.
  await page.selectOption('#tr-reference-sample', 'cat-07');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  t = await transferState(page);
  check(t.reference?.name === 'cat-07.ply' && t.step === (t.source ? 2 : 1), `after the reference: ${JSON.stringify({ reference: t.reference, step: t.step })}`);
  await page.selectOption('#tr-source-sample', 'cat');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'cat-reference.ply' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  t = await transferState(page);
  check(t.source?.name === 'cat-reference.ply' && t.sameConnectivity && t.step === 3, `after the source: ${JSON.stringify({ source: t.source, same: t.sameConnectivity, step: t.step })}`);
  check(/generated automatically/.test(await page.textContent('#tr-landmark-hint')), 'the panel does not say that landmarks are generated');
  await nextFrame(page);
  const pairPixels = await canvasPixels(page);
  // Both meshes: foreground in the left and in the right third of the view.
  const thirds = [0, 0, 0];
  for (let y = 0; y < pairPixels.h; ++y) {
    for (let x = 0; x < pairPixels.w; ++x) {
      const i = 4 * (y * pairPixels.w + x);
      const d = Math.abs(pairPixels.data[i] - background[0]) + Math.abs(pairPixels.data[i + 1] - background[1]) + Math.abs(pairPixels.data[i + 2] - background[2]);
      if (d > 30) thirds[Math.min(2, Math.floor((3 * x) / pairPixels.w))] += 1;
    }
  }
  await shot(page, '12-transfer-1-pair');
  check(thirds[0] > 100 && thirds[2] > 100, `the two meshes are not side by side (foreground pixels per third ${thirds})`);

  // Split view: two panes; orbiting the left one moves both cameras while they are linked,
  // only the right one when they are not; a landmark click lands on the pane's mesh.
  await page.check('input[name="tr-view"][value="split"]');
  await nextFrame(page);
  await shot(page, '12-transfer-1-split-linked');
  const viewBox = await page.locator('#view').boundingBox();
  const orbit = async (fx, dx) => {
    const x = viewBox.x + viewBox.width * fx;
    const y = viewBox.y + viewBox.height * 0.5;
    await page.mouse.move(x, y);
    await page.mouse.down();
    await page.mouse.move(x + dx, y + dx / 4, { steps: 8 });
    await page.mouse.up();
    await nextFrame(page);
  };
  const cameras = () => page.evaluate(() => window.__meshmorph.hooks.transferCameras());
  const apart = (a, b) => Math.hypot(...a.map((v, i) => v - b[i]));
  let before = await cameras();
  await orbit(0.25, 120);
  let after = await cameras();
  check(apart(after[0].position, before[0].position) > 0.05 && apart(after[0].position, after[1].position) < 1e-6,
    `linked split cameras: ${JSON.stringify({ before, after })}`);
  await page.uncheck('#tr-link');
  before = await cameras();
  await orbit(0.75, -160);
  after = await cameras();
  check(apart(after[1].position, before[1].position) > 0.05 && apart(after[0].position, before[0].position) < 1e-9,
    `independent split cameras: ${JSON.stringify({ before, after })}`);
  await shot(page, '12-transfer-1-split-independent');
  const splitR = await clickLandmark(page, 'reference', await visibleOnSide(page, 'reference', 'y + z'));
  const splitS = await clickLandmark(page, 'source', await visibleOnSide(page, 'source', 'y + z'));
  check(JSON.stringify((await transferState(page)).pairs) === JSON.stringify([[splitR, splitS]]), 'a pair clicked in split view');
  await nextFrame(page);
  await shot(page, '12-transfer-1-split-pair');
  await page.click('#tr-landmarks-clear');
  await page.check('#tr-link');
  await page.check('input[name="tr-view"][value="overlay"]');
  await nextFrame(page);
  await shot(page, '12-transfer-1-overlay');
  check(pixelStats(await canvasPixels(page)).foreground > 0.02, 'overlay shows nothing');
  await page.check('input[name="tr-view"][value="side"]');
  await nextFrame(page);

  // 4: run with the default method (yin), generated landmarks.
  await page.click('#tr-run');
  await page.waitForFunction(() => window.__meshmorph.state.busy, null, { timeout: 10000 }).catch(() => {});
  await shot(page, '12-transfer-2-running');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.runs >= 1 || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), `transfer failed: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  t = await transferState(page);
  const result = await page.evaluate(() => window.__meshmorph.hooks.transferResult());
  check(result.length === source.length && result.every(Number.isFinite), `result has ${result.length / 3} vertices, the source ${source.length / 3}`);
  const diagonal = bboxDiagonal(reference);
  const moved = meanDistance(result, source) / diagonal;
  const resultToReference = meanDistance(result, reference) / diagonal;
  const sourceToReference = meanDistance(source, reference) / diagonal;
  console.log(`     transfer: ${t.result.info.ms.total.toFixed(0)} ms; mean distance to the reference ${resultToReference.toFixed(3)}·diag (source ${sourceToReference.toFixed(3)}), moved ${moved.toFixed(3)}·diag; `
    + `Γ dominance ${t.result.info.gammaDominance.toFixed(2)}, ${t.result.metrics.flippedFaces} flipped faces, detail change ${t.result.metrics.laplacianChange.toFixed(3)}`);
  check(moved > 0.01, `the result is the source (moved ${moved}·diag)`);
  check(resultToReference < 0.6 * sourceToReference, `the result is not closer to the reference: ${resultToReference} against the source's ${sourceToReference}`);
  check(Math.abs(t.result.toReference.vertexErrorMean - resultToReference) < 0.1 * resultToReference, `compare op says ${t.result.toReference.vertexErrorMean}, node ${resultToReference}`);
  check(t.step === 4 && t.result.info.k > 0 && t.result.info.gamma.length === t.result.info.k ** 2 && Number.isFinite(t.result.info.gammaDominance), `result info ${JSON.stringify(t.result.info).slice(0, 300)}`);
  check(Number.isInteger(t.result.metrics.flippedFaces) && Number.isFinite(t.result.metrics.laplacianChange), `metrics ${JSON.stringify(t.result.metrics)}`);
  check(await page.isVisible('canvas.gamma-map'), 'no Γ heat map');
  check((await page.textContent('#tr-metrics')).includes('flipped faces'), 'metrics not shown');
  const shown = await page.evaluate(() => window.__meshmorph.hooks.transferShown());
  const toWelded = (r) => r; // PLY: displayed = welded (checked below)
  check(t.source.rawVertices === t.source.weldedVertices, 'the cat PLY has seams?');
  check(shown.every((v, i) => v === Math.fround(result[toWelded(i)])), 'the view does not show the result');
  await page.locator('#tr-metrics').scrollIntoViewIfNeeded();
  await nextFrame(page);
  await shot(page, '12-transfer-3-result');

  // Cancel: a second run stopped from the progress overlay leaves the first result.
  await page.click('#tr-run');
  await page.waitForFunction(() => window.__meshmorph.state.busy && document.getElementById('progress-bar').value > 0, null, { timeout: 30000 });
  const cancelStarted = Date.now();
  await page.click('#cancel');
  await waitIdle(page, 15000);
  const cancelMs = Date.now() - cancelStarted;
  record(browser, 'transferCancelMs', cancelMs);
  console.log(`     cancel of a running transfer: usable again after ${cancelMs} ms (${await page.evaluate(() => window.__meshmorph.restarts)} worker restarts)`);
  check(cancelMs < 1000, `the page was usable again only ${cancelMs} ms after Cancel`);
  const cancelled = await page.evaluate(() => window.__meshmorph.state.error);
  check(cancelled?.code === 'Cancelled', `expected a Cancelled error, got ${JSON.stringify(cancelled)}`);
  check((await transferState(page)).runs === 1 && (await page.evaluate(() => window.__meshmorph.hooks.transferResult())).every((v, i) => v === result[i]), 'the cancelled run changed the result');
  await page.click('#error-close');
  await page.evaluate(() => { window.__meshmorph.state.error = null; });

  // Toggle: the source comes back, then the result again.
  await page.check('input[name="tr-show"][value="source"]');
  const back = await page.evaluate(() => window.__meshmorph.hooks.transferShown());
  check(back.every((v, i) => v === Math.fround(source[i])), 'Source does not show the source');

  // 5: export the result as GLB.
  const [glb] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#tr-export')]);
  const glbFile = path.join(shotDir, glb.suggestedFilename());
  await glb.saveAs(glbFile);
  const bytes = fs.readFileSync(glbFile);
  check(glb.suggestedFilename() === 'cat-reference-posed.glb' && bytes.subarray(0, 4).toString('latin1') === 'glTF', `bad GLB ${glb.suggestedFilename()}`);
  const report = await (await import('gltf-validator')).validateBytes(new Uint8Array(bytes));
  check(report.issues.numErrors === 0, `posed GLB: glTF-Validator: ${JSON.stringify(report.issues.messages.slice(0, 3))}`);

  // 3: landmark pairs with the real mouse: on each side the vertex furthest towards the
  // upper front, the right front and the left front (facing the camera, away from the
  // silhouette, where a ray through the vertex could miss the surface).
  const clicked = [];
  for (const key of ['y + z', 'x + z', '-x + z']) {
    const r = await clickLandmark(page, 'reference', await visibleOnSide(page, 'reference', key));
    const s = await clickLandmark(page, 'source', await visibleOnSide(page, 'source', key));
    clicked.push([r, s]);
    if (clicked.length === 1) await shot(page, '12-transfer-4-first-pair');
  }
  t = await transferState(page);
  check(JSON.stringify(t.pairs) === JSON.stringify(clicked) && !t.pending, `pairs ${JSON.stringify(t.pairs)}, clicked ${JSON.stringify(clicked)}`);
  check(t.step === 2, `with 3 pairs (fewer than 6) the step is ${t.step}`);
  check(await page.locator('table.landmarks tbody tr').count() === 3, 'the table does not list 3 pairs');
  // Select pair 2 in the table, then delete pair 3.
  await page.click('table.landmarks tbody tr[data-index="1"]');
  check((await transferState(page)).selected === 1, 'a click on the row did not select the pair');
  await nextFrame(page);
  await shot(page, '12-transfer-5-landmarks');
  // Seen from behind, the numbers of landmarks on the far side are hidden (never drawn
  // through the mesh); every number drawn belongs to a vertex the camera sees.
  let labels = await page.evaluate(() => window.__meshmorph.hooks.transferLabels());
  check(labels.length === 6 && labels.every((l) => l.visible), `labels from the front: ${JSON.stringify(labels)}`);
  await orbit(0.5, 420);
  labels = await page.evaluate(() => window.__meshmorph.hooks.transferLabels());
  const seen = await page.evaluate((list) => list.map((l) => window.__meshmorph.hooks.transferVertexOnScreen(l.side, l.vertex, window.__meshmorph.hooks.labelTolerance).visible), labels);
  await shot(page, '12-transfer-5-landmarks-behind');
  check(labels.some((l) => !l.visible), `from behind every number is still drawn: ${JSON.stringify(labels)}`);
  check(labels.every((l, i) => l.visible === seen[i]), `numbers drawn for hidden vertices: ${JSON.stringify(labels.map((l, i) => ({ ...l, seen: seen[i] })))}`);
  await page.check('input[name="tr-view"][value="overlay"]');
  await page.check('input[name="tr-view"][value="side"]'); // frames the pair again
  await page.click('table.landmarks tbody tr[data-index="2"] .pair-delete');
  t = await transferState(page);
  check(JSON.stringify(t.pairs) === JSON.stringify(clicked.slice(0, 2)), `after deleting pair 3: ${JSON.stringify(t.pairs)}`);
  // Move pair 1's reference end: select its row, click elsewhere on the reference (the lower
  // front); the source end, the pair count and the selection stay.
  await page.click('table.landmarks tbody tr[data-index="0"]');
  check((await transferState(page)).selected === 0 && /Pair 1 selected/.test(await page.textContent('#tr-landmark-hint')),
    'selecting pair 1 did not say that a click moves it');
  clicked[0][0] = await moveLandmark(page, 'reference', 0, await visibleOnSide(page, 'reference', '-y + z'));
  t = await transferState(page);
  check(JSON.stringify(t.pairs) === JSON.stringify(clicked.slice(0, 2)) && t.selected === 0 && !t.pending,
    `after moving pair 1's reference end: ${JSON.stringify(t)}`);
  await shot(page, '12-transfer-5b-landmark-moved');
  await page.click('table.landmarks tbody tr[data-index="0"]');
  check((await transferState(page)).selected === -1, 'a second click on the row did not deselect the pair');

  // Save the landmark JSON (the CLI's format).
  const [json] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#tr-landmarks-save')]);
  const jsonFile = path.join(shotDir, json.suggestedFilename());
  await json.saveAs(jsonFile);
  const saved = JSON.parse(fs.readFileSync(jsonFile, 'utf8'));
  check(json.suggestedFilename() === 'cat-07-cat-reference.json', `landmark file name ${json.suggestedFilename()}`);
  check(saved.reference === 'cat-07.ply' && saved.source === 'cat-reference.ply' && JSON.stringify(saved.pairs) === JSON.stringify(clicked.slice(0, 2)), `saved ${JSON.stringify(saved)}`);
  // Load it back after clearing.
  await page.click('#tr-landmarks-clear');
  check((await transferState(page)).pairs.length === 0, 'Clear left pairs');
  await page.setInputFiles('#tr-landmarks-load', jsonFile);
  await page.waitForFunction((n) => window.__meshmorph.state.transfer.pairs.length === n, 2, { timeout: 5000 });
  await page.click('#tr-landmarks-clear');

  // Different connectivity (cat → lion): landmarks are needed; the repository's landmark file
  // (cat-reference indices, valid on cat-07) loads, and the Kovnatsky baseline runs with them.
  await page.selectOption('#tr-source-sample', 'lion');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'lion-reference.ply' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  t = await transferState(page);
  check(!t.sameConnectivity && t.step === 2 && !t.result, `cat → lion: ${JSON.stringify({ same: t.sameConnectivity, step: t.step })}`);
  await page.setInputFiles('#tr-landmarks-load', path.join(repoDir, 'data/landmarks/cat-lion.json'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.pairs.length === 30 || window.__meshmorph.state.error, null, { timeout: 5000 });
  check((await transferState(page)).step === 3, 'with 30 loaded pairs the next step is not Run');
  await page.selectOption('#tr-method', 'kovnatsky');
  await page.click('#tr-run');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.runs >= 2 || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), `cat → lion failed: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  t = await transferState(page);
  const lion = await page.evaluate(() => window.__meshmorph.hooks.transferResult());
  check(lion.length === 5000 * 3 && lion.every(Number.isFinite) && t.result.options.landmarks === 30 && t.result.toReference === null,
    `cat → lion result: ${lion.length / 3} vertices, ${JSON.stringify(t.result.options)}`);
  await page.locator('#tr-metrics').scrollIntoViewIfNeeded();
  await nextFrame(page);
  await shot(page, '12-transfer-6-lion-kovnatsky');
  await page.selectOption('#tr-method', 'yin');

  // Suggested pairs (cat at rest → lion): extremities on both meshes, matched; compared with
  // the repository's hand-checked landmark file, then accepted.
  await page.selectOption('#tr-reference-sample', 'cat');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference?.name === 'cat-reference.ply' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  await page.click('#tr-suggest');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.suggestions.length > 0 || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  const suggestions = (await transferState(page)).suggestions;
  const catRest = readPlyVertices(fs.readFileSync(path.join(repoDir, 'data/pose/cat-reference.ply')));
  const lionRest = readPlyVertices(fs.readFileSync(path.join(repoDir, 'data/pose/lion-reference.ply')));
  const fileLandmarks = JSON.parse(fs.readFileSync(path.join(repoDir, 'data/landmarks/cat-lion.json'), 'utf8')).pairs;
  const gap = (p, a, b) => Math.hypot(p[3 * a] - p[3 * b], p[3 * a + 1] - p[3 * b + 1], p[3 * a + 2] - p[3 * b + 2]);
  const lionDiagonal = bboxDiagonal(lionRest);
  // For each suggestion: the file's pair nearest to it on the cat, and how far the suggested
  // lion vertex is from that pair's lion vertex.
  const errors = suggestions.map(([r, sv]) => {
    const nearest = fileLandmarks.reduce((best, [fr, fs2]) => (gap(catRest, r, fr) < best.d ? { d: gap(catRest, r, fr), fs2 } : best), { d: Infinity, fs2: -1 });
    return gap(lionRest, sv, nearest.fs2) / lionDiagonal;
  });
  const agreeing = errors.filter((e) => e < 0.1).length;
  const suggested = `${suggestions.length} suggested, ${agreeing} within 0.1·diag of the landmark file`;
  record(browser, 'suggestions', suggested);
  console.log(`     landmark suggestions cat → lion: ${suggested} (errors ${errors.map((e) => e.toFixed(3)).join(', ')})`);
  check(suggestions.length >= 4 && agreeing >= 0.75 * suggestions.length, `suggestions ${JSON.stringify(suggestions)}: errors ${errors}`);
  await nextFrame(page);
  await shot(page, '12-transfer-7-suggestions');
  await page.click('#tr-suggestions tr[data-index="0"] .suggest-reject');
  await page.click('#tr-suggest-accept-all');
  t = await transferState(page);
  check(t.pairs.length === suggestions.length - 1 && t.suggestions.length === 0, `after reject 1 / accept all: ${JSON.stringify({ pairs: t.pairs, suggestions: t.suggestions })}`);
  await nextFrame(page);
  await shot(page, '12-transfer-8-suggestions-accepted');

  // glTF meshes in the pair show their own materials (the Fox's texture), the toggle gives
  // the plain colours.
  await page.selectOption('#tr-reference-sample', 'fox');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference?.name === 'Fox.gltf' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await page.selectOption('#tr-source-sample', 'cesiumman');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'CesiumMan.glb' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  await page.waitForFunction(() => Object.values(window.__meshmorph.hooks.transferMaterials()).every((m) => m === 'document'), null, { timeout: 30000 })
    .catch(async () => { throw new Error(`pair materials: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.hooks.transferMaterials()))}`); });
  let foxTexture = 0;
  for (let i = 0; i < 20 && foxTexture < 0.004; ++i) {
    await nextFrame(page);
    foxTexture = orangeShare(await canvasPixels(page));
  }
  await shot(page, '12-transfer-9-gltf-materials');
  check(foxTexture > 0.004, `the Fox's texture covers ${(foxTexture * 100).toFixed(2)}% of the pair view`);
  await page.uncheck('#tr-materials');
  check(Object.values(await page.evaluate(() => window.__meshmorph.hooks.transferMaterials())).every((m) => m === 'analysis'), 'the toggle does not give the plain colours');
  await page.check('#tr-materials');

  // Back to the Mesh job: its mesh is shown again.
  await page.click('#jobs button[data-job="mesh"]');
  await nextFrame(page);
  check(pixelStats(await canvasPixels(page)).foreground > 0.02, 'the Mesh job shows nothing after the Transfer job');
  check(pageErrors.length === errorsBefore, `uncaught page errors: ${pageErrors.slice(errorsBefore).join(' | ')}`);
});

// Hierarchical part transfer (paper 000 Sec. 4.3, issue 16) in the page: the crouching cat
// (pose 01) onto the cat at rest, Parts = automatic. The worker runs `partTransfer`; the page
// lists the proposed parts with the core's verdict, colours them on the source side, shows the
// level-1 result beside the final one, saves the part pairs (the CLI's --parts JSON), and a run
// from that file gives the same mesh again. The same op in node equals the page bit for bit;
// the native CLI keeps the same parts, its mesh within the native/wasm difference.
const centredMeanDistance = (a, b) => {
  const n = a.length / 3;
  const ca = [0, 0, 0], cb = [0, 0, 0];
  for (let i = 0; i < n; ++i) for (let k = 0; k < 3; ++k) { ca[k] += a[3 * i + k] / n; cb[k] += b[3 * i + k] / n; }
  let sum = 0;
  for (let i = 0; i < n; ++i) sum += Math.hypot(...[0, 1, 2].map((k) => (a[3 * i + k] - ca[k]) - (b[3 * i + k] - cb[k])));
  return sum / n;
};
const maxDistance = (a, b) => {
  let m = 0;
  for (let i = 0; i < a.length; i += 3) m = Math.max(m, Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
  return m;
};

it('transfer parts: automatic parts on the crouching cat — proposed, transferred again and glued, coloured, saved and run again from the file; the CLI agrees', async ({ page, pageErrors, browser }) => {
  const errorsBefore = pageErrors.length;
  const referenceFile = path.join(repoDir, 'data/pose/cat-01.ply');
  const sourceFile = path.join(repoDir, 'data/pose/cat-reference.ply');
  const reference = readPlyVertices(fs.readFileSync(referenceFile));
  const diagonal = bboxDiagonal(reference);
  await loadCount(page);
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.click('#jobs button[data-job="transfer"]');
  await page.waitForSelector('#tr-steps', { state: 'visible' });
  await page.selectOption('#tr-reference-sample', 'cat-01');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference?.name === 'cat-01.ply' || window.__meshmorph.state.error, null, { timeout: 30000 });
  await waitIdle(page);
  if ((await transferState(page)).source?.name !== 'cat-reference.ply') {
    await page.selectOption('#tr-source-sample', 'cat');
    await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'cat-reference.ply' || window.__meshmorph.state.error, null, { timeout: 30000 });
    await waitIdle(page);
  }
  let t = await transferState(page);
  check(t.sameConnectivity && t.step === 3 && t.pairs.length === 0, `cat-01 → cat: ${JSON.stringify({ same: t.sameConnectivity, step: t.step, pairs: t.pairs })}`);
  await page.selectOption('#tr-method', 'yin');
  // Parts: none hides the part options; automatic shows them and says what happens.
  check(!(await page.isVisible('#tr-part-options .lil-gui')), 'part options shown with Parts = none');
  await page.selectOption('#tr-parts', 'auto');
  check(await page.isVisible('#tr-part-options .lil-gui') && /proposed/.test(await page.textContent('#tr-parts-hint')), 'Parts = automatic: no part options or hint');
  // One round of three candidate sets of at most three parts, set in the part options form: this
  // case checks the page's workflow (the form's values reach the op, the parts, the file, the
  // CLI); the quality of the default three rounds of six is asserted on every pair by the C++
  // suite. (CI time, twenty-fifth session: the defaults made this the longest e2e case, 139 s.)
  await page.click('#tr-part-options .lil-title');
  await page.waitForSelector('#opt-max_parts', { state: 'visible' });
  check((await page.inputValue('#opt-max_parts')) === '6' && (await page.inputValue('#opt-proposal_rounds')) === '3',
    `part options start at max_parts ${await page.inputValue('#opt-max_parts')}, proposal_rounds ${await page.inputValue('#opt-proposal_rounds')}`);
  await page.fill('#opt-max_parts', '3');
  await page.fill('#opt-proposal_rounds', '1');
  await page.click('#tr-part-options .lil-title');
  const partOptions = { max_parts: 3, proposal_rounds: 1 };
  const runs = t.runs;
  const runStarted = Date.now();
  await page.click('#tr-run');
  await page.waitForFunction((n) => window.__meshmorph.state.transfer.runs > n || window.__meshmorph.state.error, runs, { timeout: 120000 });
  await waitIdle(page, 120000);
  const runMs = Date.now() - runStarted;
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), `part transfer failed: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  t = await transferState(page);
  const parts = t.result.parts.info.parts;
  const kept = parts.filter((p) => p.ok && !p.rejected);
  const result = await page.evaluate(() => window.__meshmorph.hooks.transferResult());
  const level1 = await page.evaluate(() => window.__meshmorph.hooks.transferLevel1());
  const e1 = centredMeanDistance(level1, reference) / diagonal;
  const e2 = centredMeanDistance(result, reference) / diagonal;
  const f = t.result.parts.info.folds;
  console.log(`     parts: ${kept.length} of ${parts.length} kept (${parts.map((p) => `${p.name.replace(/ \(.*/, '')}: ${p.ok && !p.rejected ? 'kept' : p.message}`).join('; ')}); `
    + `mean distance to the reference ${e1.toFixed(4)} → ${e2.toFixed(4)}·diag; self-intersections ${f.level1} → ${f.result}, flips ${f.flipsLevel1} → ${f.flips}; ${runMs} ms (worker ${t.result.parts.info.ms.total.toFixed(0)} ms)`);
  check(parts.length >= 1 && kept.length >= 1, `no part kept: ${JSON.stringify(parts)}`);
  check(e2 < e1, `two levels are not closer to the reference: ${e2} against level 1's ${e1}`);
  check(f.flips <= f.flipsLevel1 && f.result <= Math.max(f.reference + f.source, f.level1), `parts added folds: ${JSON.stringify(f)}`);
  check(await page.locator('#tr-parts-result tbody tr').count() === parts.length, 'the parts table does not list every part');
  check((await page.textContent('#tr-metrics')).includes('self-intersections'), 'no fold report under the metrics');
  // Colours: every kept part's vertices in its own colour, the rest plain.
  const colors = await page.evaluate(() => window.__meshmorph.hooks.transferColors());
  check(colors && colors.length === result.length, 'the parts are not coloured');
  const distinct = new Set();
  for (let i = 0; i < colors.length; i += 3) distinct.add(colors.slice(i, i + 3).map((c) => c.toFixed(3)).join());
  check(distinct.size >= 2, `${distinct.size} colours for ${parts.length} parts`);
  await page.locator('#tr-parts-result').scrollIntoViewIfNeeded();
  await nextFrame(page);
  await shot(page, '12-transfer-10-parts');
  // Level 1: the whole-body result before the parts.
  await page.check('input[name="tr-show"][value="level1"]');
  const shown1 = await page.evaluate(() => window.__meshmorph.hooks.transferShown());
  check(shown1.every((v, i) => v === Math.fround(level1[i])), 'Level 1 does not show the level-1 result');
  await page.uncheck('#tr-part-colours');
  check(!(await page.evaluate(() => window.__meshmorph.hooks.transferColors())), 'the colours stay after unchecking');
  await nextFrame(page);
  await shot(page, '12-transfer-11-parts-level1');
  await page.check('#tr-part-colours');
  await page.check('input[name="tr-show"][value="result"]');

  // The same op in node on the wasm module's node build (tests/js/wasm_module.mjs): the page's
  // result bit for bit.
  const { makeContext } = await import('../js/wasm_module.mjs');
  const { ops: meshOps } = await import('../../web/src/worker/ops/mesh.js');
  const { ops: transferOps } = await import('../../web/src/worker/ops/transfer.js');
  const ctx = await makeContext();
  meshOps.load(ctx, { name: 'cat-01.ply', slot: 'reference' }, { 'cat-01.ply': new Uint8Array(fs.readFileSync(referenceFile)) });
  meshOps.load(ctx, { name: 'cat-reference.ply', slot: 'source' }, { 'cat-reference.ply': new Uint8Array(fs.readFileSync(sourceFile)) });
  const inNode = transferOps.partTransfer(ctx, { referenceSlot: 'reference', sourceSlot: 'source', method: 'yin', parts: 'auto', partOptions }).buffers.positions;
  check(inNode.length === result.length && inNode.every((v, i) => v === result[i]), `the page and the node wasm module differ (max ${maxDistance(inNode, result) / diagonal}·diag)`);
  // The CLI on the same files (native build) with the parts the page kept (its proposal set:
  // automatic parts try several sets and keep the one whose landmarks land closest, and where two
  // sets come close the builds' last bits can pick differently — docs/transfer.md): the same
  // parts kept; the mesh within the native/wasm difference of the parts' own transfers (the
  // eigensolver's last bits, amplified on near-cylindrical limbs; measured up to 4.7e-3 of the
  // diagonal on the lion's leg and paw).
  const cliOut = path.join(shotDir, 'cat01-parts-cli.ply');
  const cliParts = path.join(shotDir, 'cat01-parts-cli.json');
  const pageParts = path.join(shotDir, 'cat01-parts-page.json');
  fs.writeFileSync(pageParts, t.result.parts.info.partsJson);
  const proposals = t.result.parts.info.proposals;
  check(proposals && proposals.tried >= 2 && proposals.rounds <= 1 && proposals.kept < proposals.tried && proposals.landmarkError <= proposals.landmarkErrorLevel1,
    `proposal sets: ${JSON.stringify(proposals)}`);
  check(proposals.tried < 2 || await page.isVisible('#tr-parts-proposals'), 'the proposal sets tried are not shown');
  // The CLI on the page's parts (Chromium only: Firefox runs the same wasm op, and its page
  // result is compared with Chromium's numbers in the log — CI time, twenty-second session).
  if (browser !== 'firefox') {
    const run = spawnSync(cliPath, ['transfer', '--reference', referenceFile, '--source', sourceFile, '--parts', pageParts, '--out', cliOut, '--parts-out', cliParts], { encoding: 'utf8', timeout: 120000 });
    check(run.status === 0, `meshmorph transfer --parts (the page's) failed (${run.status}): ${run.stderr}`);
    const cli = readPlyVertices(fs.readFileSync(cliOut));
    const cliDifference = maxDistance(cli, result) / diagonal;
    const cliKept = (run.stdout.match(/(\d+) kept/) || [])[1];
    // Which parts each kept, in transfer order (the CLI prints one line per part, "skipped: ..." on
    // the ones it did not keep).
    const cliVerdicts = run.stdout.split('\n').filter((l) => /^ {4}level \d/.test(l)).map((l) => !/skipped:/.test(l));
    const pageVerdicts = parts.map((p) => p.ok && !p.rejected);
    const sameParts = cliVerdicts.length === pageVerdicts.length && cliVerdicts.every((k, i) => k === pageVerdicts[i]);
    const cliError = centredMeanDistance(cli, reference) / diagonal;
    console.log(`     proposal sets: ${proposals.tried} tried in ${proposals.rounds} round(s), set ${proposals.kept + 1} kept; page vs CLI (the page's parts): max vertex difference ${cliDifference.toExponential(2)}·diag; CLI kept ${cliKept} of ${JSON.parse(fs.readFileSync(cliParts, 'utf8')).parts.length}, the page ${kept.length} (${sameParts ? 'the same parts' : `not the same parts: CLI ${cliVerdicts.map(Number).join('')}, page ${pageVerdicts.map(Number).join('')}`}); mean distance to the reference: page ${e2.toFixed(4)}, CLI ${cliError.toFixed(4)} (level 1 ${e1.toFixed(4)})`);
    // The builds' part transfers differ in their last bits (the eigensolver's, amplified on limbs),
    // and with three rounds of parts a part near the gate's thresholds can be kept by one build and
    // rejected by the other (docs/transfer.md: cat-01 measured 6 against 7 of 8 kept, 0.11·diag
    // apart at that part; and 7 of 10 each, but not the same 7, 5.7e-2·diag apart). So: where both
    // keep the same parts, the meshes agree to 2e-2·diag; either way the CLI's result on the page's
    // parts is closer to the reference than level 1, by a gain within half of the page's.
    if (sameParts) check(cliDifference < 2e-2, `page and CLI keep the same parts and differ by ${cliDifference}·diag`);
    check(cliError < e1 && Math.abs(cliError - e2) <= 0.5 * (e1 - e2), `the CLI on the page's parts: mean distance ${cliError} against the page's ${e2} (level 1 ${e1})`);
  }

  // Save parts → load the file → Parts: from file → the same mesh.
  const [saved] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#tr-parts-save')]);
  const partsFile = path.join(shotDir, saved.suggestedFilename());
  await saved.saveAs(partsFile);
  const savedParts = JSON.parse(fs.readFileSync(partsFile, 'utf8'));
  check(saved.suggestedFilename() === 'cat-01-cat-reference-parts.json' && savedParts.parts.length === parts.length, `saved parts ${saved.suggestedFilename()}: ${JSON.stringify(savedParts).slice(0, 200)}`);
  await page.setInputFiles('#tr-parts-load', partsFile);
  await page.waitForFunction(() => window.__meshmorph.state.transfer.parts === 'file', null, { timeout: 5000 });
  check(new RegExp(`${parts.length} part pair`).test(await page.textContent('#tr-parts-hint')), `hint after loading: ${await page.textContent('#tr-parts-hint')}`);
  await page.click('#tr-run');
  await page.waitForFunction((n) => window.__meshmorph.state.transfer.runs > n || window.__meshmorph.state.error, runs + 1, { timeout: 120000 });
  await waitIdle(page, 120000);
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), `run from the part file failed: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  const again = await page.evaluate(() => window.__meshmorph.hooks.transferResult());
  const againDifference = maxDistance(again, result) / diagonal;
  console.log(`     run again from the saved part file: max difference ${againDifference.toExponential(2)}·diag`);
  check(againDifference === 0, `the saved parts give another mesh (${againDifference}·diag)`);
  // A malformed part file is refused with a message; the loaded one stays.
  const badFile = path.join(shotDir, 'bad-parts.json');
  fs.writeFileSync(badFile, '{"parts": 3}');
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.setInputFiles('#tr-parts-load', badFile);
  await page.waitForFunction(() => window.__meshmorph.state.error, null, { timeout: 5000 });
  const refused = await page.evaluate(() => window.__meshmorph.state.error);
  check(refused.code === 'ParseError' && /bad-parts\.json/.test(refused.message) && (await transferState(page)).parts === 'file', `bad part file: ${JSON.stringify(refused)}`);
  await page.click('#error-close');
  await page.evaluate(() => { window.__meshmorph.state.error = null; });

  // Export: the final result.
  const [glb] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click('#tr-export')]);
  const glbFile = path.join(shotDir, `parts-${glb.suggestedFilename()}`);
  await glb.saveAs(glbFile);
  const report = await (await import('gltf-validator')).validateBytes(new Uint8Array(fs.readFileSync(glbFile)));
  check(report.issues.numErrors === 0, `parts GLB: glTF-Validator: ${JSON.stringify(report.issues.messages.slice(0, 3))}`);
  await page.selectOption('#tr-parts', 'none');
  await page.click('#jobs button[data-job="mesh"]');
  check(pageErrors.length === errorsBefore, `uncaught page errors: ${pageErrors.slice(errorsBefore).join(' | ')}`);
});

// ---- recovery: the worker runs out of memory or dies; the page replaces it

const bigMeshFile = () => writeBigMesh(path.join(repoDir, 'data/edit/armadillo.ply'), path.join(shotDir, 'armadillo-1m.ply'));

it('recovery: a 1M-vertex mesh, a full wasm heap and a dead worker never take the page down; the meshes come back', async ({ context, baseUrl, consoleLines: lines }) => {
  const page = await context.newPage();
  await page.setViewportSize({ width: 1280, height: 800 });
  page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') lines.push(`[page 2 ${m.type()}] ${m.text()}`); });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`${baseUrl}?sample=hand`);
  await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1, null, { timeout: 60000 });
  await waitIdle(page);
  // The Transfer job's two meshes, to be restored as well.
  await page.click('#jobs button[data-job="transfer"]');
  await page.click('#tr-example');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  await page.click('#jobs button[data-job="mesh"]');

  // 1. The 1M-vertex mesh (armadillo, every triangle split into 81) opens through the picker.
  const big = bigMeshFile();
  const started = Date.now();
  await page.setInputFiles('#file', big);
  await page.waitForFunction(() => window.__meshmorph.state.loads >= 2 || window.__meshmorph.state.error, null, { timeout: 240000 });
  await waitIdle(page, 240000);
  const loaded = await page.evaluate(() => ({ mesh: window.__meshmorph.state.mesh, error: window.__meshmorph.state.error, read: window.__meshmorph.state.lastReadMs, ms: window.__meshmorph.state.lastLoadMs }));
  const loadSeconds = (Date.now() - started) / 1000;
  if (loaded.ms) console.log(`     1M-vertex load stages: file read ${loaded.read?.toFixed(0)} ms, worker op ${loaded.ms.worker.toFixed(0)} ms, view geometry ${loaded.ms.view.toFixed(0)} ms`);
  measured.bigMesh = loaded.error ? `refused: ${loaded.error.code} ${loaded.error.message}` : `${loaded.mesh.weldedVertices} vertices loaded in ${loadSeconds.toFixed(1)} s`;
  console.log(`     1M-vertex PLY (${(fs.statSync(big).size / 2 ** 20).toFixed(0)} MB): ${measured.bigMesh}`);
  await nextFrame(page);
  await shot(page, '13-recovery-1-big-mesh');
  check(!loaded.error ? loaded.mesh.weldedVertices > 1000000 : /limit|memory/i.test(loaded.error.message), `1M mesh: ${JSON.stringify(loaded)}`);

  // 2. The wasm heap is full (what a 1M-vertex eigenbasis reaches after minutes): the next
  //    op fails with OutOfMemory, the worker is replaced and every mesh is loaded again.
  const heap = await page.evaluate(() => window.__meshmorph.client.run('debugExhaustMemory').promise.then((r) => r.info.allocatedMB));
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await computeBasis(page, 20);
  await page.waitForFunction(() => window.__meshmorph.state.recoveries >= 1, null, { timeout: 300000 });
  await waitIdle(page, 300000);
  let state = await page.evaluate(() => ({ error: window.__meshmorph.state.error, recovery: window.__meshmorph.state.recovery, restarts: window.__meshmorph.restarts, banner: document.getElementById('error').textContent }));
  console.log(`     heap filled to ${heap.toFixed(0)} MB → ${state.error?.code}; ${state.recovery?.text}`);
  await shot(page, '13-recovery-2-out-of-memory');
  check(state.error?.code === 'OutOfMemory' && state.restarts === 1, `after the heap filled: ${JSON.stringify(state)}`);
  check(['mesh:main', 'mesh:transfer-reference', 'mesh:transfer-source'].every((k) => state.recovery.restored.includes(k)), `restored ${state.recovery.restored}`);
  check(/out of memory/i.test(state.banner) && /restored/.test(state.banner), `the message does not say what happened: ${state.banner}`);
  // The new worker has the meshes: the big one in the Mesh job, the cat pair in the Transfer job.
  const mainVertices = await page.evaluate(() => window.__meshmorph.client.run('validate', {}).promise.then((r) => r.info.report.vertices));
  check(mainVertices === loaded.mesh?.weldedVertices || loaded.error, `the Mesh job's mesh in the new worker has ${mainVertices} vertices`);
  await page.click('#jobs button[data-job="transfer"]');
  await page.click('#tr-suggest');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.suggestions.length > 0 || window.__meshmorph.state.error?.code !== 'OutOfMemory', null, { timeout: 60000 });
  await waitIdle(page);
  check((await transferState(page)).suggestions.length > 0, `the transfer meshes were not restored: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  await page.click('#jobs button[data-job="mesh"]');

  // 3. The worker dies (an uncaught error): replaced the same way (a small mesh first, so the
  //    replay is quick).
  await pickSample(page, 'skull');
  await page.evaluate(() => { window.__meshmorph.state.error = null; window.__meshmorph.client.run('debugCrash').promise.catch(() => {}); });
  await page.waitForFunction(() => window.__meshmorph.state.recoveries >= 2, null, { timeout: 60000 });
  await waitIdle(page);
  state = await page.evaluate(() => ({ recovery: window.__meshmorph.state.recovery, restarts: window.__meshmorph.restarts, status: document.getElementById('status').textContent }));
  check(state.restarts === 2 && /restored/.test(state.status), `after the worker died: ${JSON.stringify(state)}`);
  await computeBasis(page, 10);
  await page.waitForFunction(() => window.__meshmorph.state.eigen?.k === 10 || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  check(await page.evaluate(() => window.__meshmorph.state.eigen?.k === 10), `no eigenbasis after the restart: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  await nextFrame(page);
  await shot(page, '13-recovery-3-after-crash');
  check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  await page.close();
});

// ---- jobs with their own test files

registerMergeTests(it, { check, shot, nextFrame, waitIdle, canvasPixels, pixelStats, repoDir, shotDir, cliPath });
registerRetargetTests(it, { check, shot, nextFrame, waitIdle, canvasPixels, pixelStats, repoDir, shotDir, cliPath, record });

// The Open… pickers of the two-mesh jobs (the other cases load bundled samples): a person's own
// PLY pair into Transfer and a mesh into Merge's source, through the file inputs.
it('transfer: the Open… pickers take the person\'s own files (Transfer and Merge)', async ({ page }) => {
  await page.waitForFunction(() => window.__meshmorph.state.loads >= 1, null, { timeout: 60000 });
  await waitIdle(page);  // the pickers are disabled while the worker is busy
  // An error an earlier case provoked on purpose (Firefox shares one page: the retarget case
  // before this one ends on a refused joint file) is not this case's.
  await page.evaluate(() => { window.__meshmorph.state.error = null; });
  await page.click('#jobs button[data-job="transfer"]');
  await page.setInputFiles('#tr-reference-file', path.join(repoDir, 'data/pose/cat-07.ply'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference?.name === 'cat-07.ply' || window.__meshmorph.state.error, null, { timeout: 60000 });
  await page.setInputFiles('#tr-source-file', path.join(repoDir, 'data/pose/cat-reference.ply'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'cat-reference.ply' || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  const t = await page.evaluate(() => ({ ref: window.__meshmorph.state.transfer.reference, src: window.__meshmorph.state.transfer.source, same: window.__meshmorph.state.transfer.sameConnectivity, error: window.__meshmorph.state.error }));
  check(!t.error && t.ref?.weldedVertices === 7207 && t.src?.weldedVertices === 7207 && t.same, `transfer pickers: ${JSON.stringify(t)}`);
  await shot(page, '16-transfer-own-files');
  await page.click('#jobs button[data-job="merge"]');
  await waitIdle(page);
  await page.setInputFiles('#mg-source-file', path.join(repoDir, 'data/edit/camelhead.ply'));
  await page.waitForFunction(() => window.__meshmorph.state.merge.source?.name === 'camelhead.ply' || window.__meshmorph.state.error, null, { timeout: 60000 });
  await waitIdle(page);
  check(!(await page.evaluate(() => window.__meshmorph.state.error)), `merge picker: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
  await shot(page, '16-merge-own-file');
});

it('no console warnings or errors during the run', async ({ allConsole }) => {
  check(allConsole.length === 0, `${allConsole.length} console lines:\n${allConsole.slice(0, 20).join('\n')}`);
});

// ---- runner

// The tests that also run in Firefox (by name prefix).
// (Not 'transfer parts: ', since the twenty-fourth session: see below.)
const firefoxTests = ['page loads', 'the default sample mesh renders', 'glTF materials', 'edit: ', 'transfer: ', 'retarget: ', 'merge: ', 'no console'];
// Left to Chromium (CI time, eleventh session): the longest Firefox case (~21 s), whose controls
// and worker ops the other Firefox retarget cases (Knight → Barbarian, Fox → wolf with automatic
// joints and a pin, the person's own files) already drive. Twenty-fourth session: the automatic
// parts case is not in the list above either (~140 s in Firefox, the CI's longest e2e case; the
// same wasm op and controls as the Firefox transfer case's Run, and Chromium checks the parts, the
// file and the CLI).
// Twenty-fifth session (CI time): the automatic-joints case (~39 s in Firefox; its joint drag is
// the same pointer handling as the Firefox edit case's gizmo drag, and the fit is the same wasm op
// as Chromium's) and the dependent merge (~11 s; the same merge op and controls as the Firefox
// merge case) are left to Chromium too.
const firefoxSkip = ['retarget: KayKit clip onto the bundled human woman', 'retarget: automatic joints', 'merge: dependent mode'];

// Installed in every page before its own scripts: the long-task observer (Chromium) and a
// drop helper that dispatches dragenter / dragover / drop with a file at a fraction of the
// view's width (tests/e2e only; the page does not know about either).
function pageHelpers() {
  window.__longTasks = null; // null: the browser has no long-task entries (Firefox)
  if (PerformanceObserver.supportedEntryTypes?.includes('longtask')) {
    window.__longTasks = [];
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) window.__longTasks.push({ start: e.startTime, duration: e.duration });
    }).observe({ type: 'longtask', buffered: true });
  }
  // Long animation frames (Chromium): which scripts made a slow frame (diagnostics only).
  window.__longFrames = null;
  if (PerformanceObserver.supportedEntryTypes?.includes('long-animation-frame')) {
    window.__longFrames = [];
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) {
        window.__longFrames.push({
          start: e.startTime, duration: e.duration, blocking: e.blockingDuration, render: e.renderStart ? e.startTime + e.duration - e.renderStart : 0,
          scripts: e.scripts.map((x) => `${x.invoker} ${x.sourceFunctionName || ''}@${(x.sourceURL || '').split('/').pop()}:${x.sourceCharPosition} ${x.duration.toFixed(0)}ms`),
        });
      }
    }).observe({ type: 'long-animation-frame', buffered: true });
  }
  window.__dropFile = (b64, name, fx) => {
    const raw = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const dataTransfer = new DataTransfer();
    dataTransfer.items.add(new File([raw], name, { type: 'application/octet-stream' }));
    const rect = document.getElementById('view').getBoundingClientRect();
    const init = { clientX: rect.left + rect.width * fx, clientY: rect.top + rect.height / 2, dataTransfer, bubbles: true, cancelable: true };
    const viewport = document.getElementById('viewport');
    for (const type of ['dragenter', 'dragover', 'drop']) viewport.dispatchEvent(new DragEvent(type, init));
  };
}

// True when build/web-dist is missing or older than the page sources or the wasm module.
function pageIsStale() {
  const built = path.join(distDir, 'index.html');
  if (!fs.existsSync(built)) return true;
  const builtAt = fs.statSync(built).mtimeMs;
  const wasmDir = path.resolve(repoDir, process.env.MM_WASM_DIR || 'build/wasm/wasm');
  const inputs = [path.join(wasmDir, 'meshmorph_web.mjs'), path.join(wasmDir, 'meshmorph_web.wasm')];
  const walk = (dir) => {
    for (const entry of fs.readdirSync(dir, { withFileTypes: true })) {
      const full = path.join(dir, entry.name);
      if (entry.isDirectory()) walk(full);
      else inputs.push(full);
    }
  };
  walk(path.join(repoDir, 'web'));
  return inputs.some((f) => fs.existsSync(f) && fs.statSync(f).mtimeMs > builtAt);
}

// A static server for build/web-dist without the isolation headers (the fallback test).
async function plainServer(root) {
  const http = await import('node:http');
  const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css', '.wasm': 'application/wasm', '.json': 'application/json' };
  const server = http.createServer((req, res) => {
    const rel = decodeURIComponent(new URL(req.url, 'http://x').pathname).replace(/^\/+/, '') || 'index.html';
    const file = path.join(root, rel);
    if (!file.startsWith(root) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
    fs.createReadStream(file).pipe(res);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return server;
}

async function main() {
  fs.mkdirSync(shotDir, { recursive: true });
  if (process.env.MM_E2E_BUILD === '1' || pageIsStale()) {
    console.log('building the page (vite build)…');
    await build({ configFile, logLevel: 'warn' });
  }
  const port = await freePort();
  const server = await preview({ configFile, logLevel: 'warn', preview: { host: '127.0.0.1', port, strictPort: true, open: false } });
  const baseUrl = `http://127.0.0.1:${port}/`;
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'meshmorph-e2e-'));
  let context = null;
  let passed = 0;
  let failed = 0;
  try {
    context = await chromium.launchPersistentContext(userDataDir, {
      executablePath: process.env.MM_CHROMIUM || '/usr/bin/chromium',
      headless: !args.includes('--headed'),
      acceptDownloads: true,
      viewport: { width: 1280, height: 800 },
      args: [
        '--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--ignore-gpu-blocklist',
        '--disable-background-networking', '--disable-component-update', '--disable-default-apps', '--disable-sync',
        '--disable-extensions', '--no-first-run', '--no-default-browser-check', '--disable-dev-shm-usage', '--mute-audio',
      ],
    });
    await context.addInitScript(pageHelpers);
    const page = context.pages()[0] || (await context.newPage());
    const pageErrors = [];
    page.on('pageerror', (e) => pageErrors.push(e.message));
    // Every console warning or error fails the last test (the page logs handled errors as
    // info); each test's lines are also shown with its failure.
    let consoleLines = [];
    const allConsole = [];
    page.on('console', (m) => {
      if (m.type() !== 'error' && m.type() !== 'warning') return;
      consoleLines.push(`[page ${m.type()}] ${m.text()}`);
    });
    await page.goto(baseUrl);
    for (const t of tests) {
      if (only && !t.name.includes(only) && !t.name.startsWith('no console')) continue;
      if (args.includes('--firefox-only')) continue;
      const started = Date.now();
      consoleLines = [];
      try {
        await t.fn({ page, context, baseUrl, pageErrors, allConsole, consoleLines, browser: 'chromium' });
        allConsole.push(...consoleLines.map((l) => `${t.name}: ${l}`));
        passed += 1;
        console.log(`ok   ${t.name} (${Date.now() - started} ms)`);
      } catch (e) {
        failed += 1;
        allConsole.push(...consoleLines.map((l) => `${t.name}: ${l}`));
        console.log(`FAIL ${t.name} (${Date.now() - started} ms)\n     ${String(e.message || e).split('\n').join('\n     ')}`);
        for (const line of consoleLines) console.log(`     ${line}`);
        await shot(page, `fail-${tests.indexOf(t)}`).catch(() => {});
      }
    }
  } catch (e) {
    failed += 1;
    console.log(`FAIL setup: ${e.stack || e}`);
  } finally {
    await context?.close().catch(() => {});
  }
  // The same tests in Firefox ESR (puppeteer-core, WebDriver BiDi, headed under Xvfb): the page
  // basics, the glTF materials, the Edit and the Transfer workflows and the console check.
  try {
    const missing = firefoxMissing();
    if (args.includes('--no-firefox')) {
      console.log('skip [firefox] all Firefox tests (--no-firefox)');
    } else if (missing) {
      console.log(`skip [firefox] all Firefox tests: ${missing}`);
    } else {
      const selected = tests.filter((t) => firefoxTests.some((prefix) => t.name.startsWith(prefix)) && !firefoxSkip.some((prefix) => t.name.startsWith(prefix)) && (!only || t.name.includes(only) || t.name.startsWith('no console')));
      const ff = await runInFirefox({ tests: selected, baseUrl, initScripts: [pageHelpers], shotDir });
      console.log(`firefox ${ff.version}: ${ff.passed} passed, ${ff.failed} failed`);
      passed += ff.passed;
      failed += ff.failed;
    }
  } catch (e) {
    failed += 1;
    console.log(`FAIL [firefox] setup: ${e.stack || e}`);
  } finally {
    await new Promise((resolve) => server.httpServer.close(resolve));
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
  for (const [name, value] of Object.entries(measured)) console.log(`measured ${name}: ${value}`);
  console.log(`screenshots: ${path.relative(process.cwd(), shotDir) || '.'}/`);
  console.log(`${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

main();
