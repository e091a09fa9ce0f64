// Browser end-to-end tests of the page: playwright-core drives Debian's /usr/bin/chromium
// (headless, WebGL through SwiftShader) against the built page (build/web-dist; rebuilt here
// when missing, older than web/ or the wasm module, or MM_E2E_BUILD=1) served by `vite
// preview` on 127.0.0.1 and a free port.
// Screenshots (and the exported GLB) go to build/e2e/ or MM_E2E_OUT. Prints "N passed, M
// failed"; exit code 1 on any failure.
//
// Usage: node tests/e2e/run.mjs [--headed] [--only <substring>]
// Env:   MM_CHROMIUM (default /usr/bin/chromium), MM_E2E_BUILD=1 (rebuild the page first),
//        MM_E2E_OUT (output directory), MM_WASM_DIR (the wasm build, as for vite.config.js)
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { build, preview } from 'vite';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const configFile = path.join(repoDir, 'web/vite.config.js');
const distDir = path.join(repoDir, 'build/web-dist');
const shotDir = path.resolve(process.env.MM_E2E_OUT || path.join(repoDir, 'build/e2e'));
const args = process.argv.slice(2);
const only = args.includes('--only') ? args[args.indexOf('--only') + 1] : null;
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

// ---- the tests (run in order; later ones build on the page state of earlier ones)

const tests = [];
const it = (name, fn) => tests.push({ name, fn });

it('page loads, worker and wasm module start', async ({ page, pageErrors }) => {
  await page.waitForFunction(() => window.__meshmorph?.state.ready, null, { timeout: 60000 });
  const mode = await page.evaluate(() => window.__meshmorph.cancelMode);
  check(mode === 'cooperative', `page is not crossOriginIsolated (cancel mode ${mode}); COOP/COEP headers missing?`);
  check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
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
  check(/λ₇ = [0-9.e+-]+/.test(label), `eigenvalue label: ${label}`);
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

// ---- runner

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
    const page = context.pages()[0] || (await context.newPage());
    const pageErrors = [];
    page.on('pageerror', (e) => pageErrors.push(e.message));
    // Console output is shown for failed tests only: the page logs every error it displays,
    // and the malformed-file test provokes several on purpose.
    let consoleLines = [];
    page.on('console', (m) => { if (m.type() === 'error' || m.type() === 'warning') consoleLines.push(`[page ${m.type()}] ${m.text()}`); });
    await page.goto(baseUrl);
    for (const t of tests) {
      if (only && !t.name.includes(only)) continue;
      const started = Date.now();
      consoleLines = [];
      try {
        await t.fn({ page, context, baseUrl, pageErrors });
        passed += 1;
        console.log(`ok   ${t.name} (${Date.now() - started} ms)`);
      } catch (e) {
        failed += 1;
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
    await new Promise((resolve) => server.httpServer.close(resolve));
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
  console.log(`screenshots: ${path.relative(process.cwd(), shotDir) || '.'}/`);
  console.log(`${passed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
}

main();
