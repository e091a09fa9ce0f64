// Drag bench (issue 12's figures, reported, not asserted): in headless Chromium, an Edit session
// on the armadillo (14 587 vertices) and on the armadillo with every triangle split into 4
// (58 342 vertices) gets its gizmo arrow dragged with the real mouse for a few seconds; prints the
// rendered frames per second of the view, the editDrag answers per second (the mesh following
// the gizmo) and the longest main-thread task (long-task observer) during the drag.
// Needs the built page (node tests/e2e/run.mjs builds it; or `npm run build`).
// Usage: MM_WASM_DIR=… node tests/e2e/drag-bench.mjs [seconds = 4]
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { preview } from 'vite';
import { binaryPly, readBinaryPly, subdivide } from './big-mesh.mjs';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const outDir = path.resolve(process.env.MM_E2E_OUT || path.join(repoDir, 'build/e2e'));
const seconds = Number(process.argv[2] || 4);

function spec(positions) {
  const n = positions.length / 3;
  const order = (key) => [...Array(n).keys()].sort((a, b) => key(b) - key(a));
  const x = (v) => positions[3 * v];
  const y = (v) => positions[3 * v + 1];
  const handle = order(x).slice(0, Math.round(0.03 * n)).sort((a, b) => a - b);   // the right hand
  const fixed = order((v) => -y(v)).slice(0, Math.round(0.05 * n)).sort((a, b) => a - b); // the feet
  return { handles: [{ select: handle }], fixed, features: 'keep' };
}

async function bench(page, file, label) {
  const mesh = readBinaryPly(fs.readFileSync(file));
  const specFile = path.join(outDir, `${path.basename(file, '.ply')}.bench.edit.json`);
  fs.writeFileSync(specFile, JSON.stringify(spec(mesh.positions)));
  await page.click('#jobs button[data-job="mesh"]');
  const loads = await page.evaluate(() => window.__meshmorph.state.loads);
  await page.setInputFiles('#file', file);
  await page.waitForFunction((n) => window.__meshmorph.state.loads > n && !window.__meshmorph.state.busy, loads, { timeout: 120000 });
  await page.click('#jobs button[data-job="edit"]');
  await page.setInputFiles('#edit-load', specFile);
  await page.waitForFunction(() => (window.__meshmorph.state.edit.session || window.__meshmorph.state.error) && !window.__meshmorph.state.busy, null, { timeout: 120000 });
  const error = await page.evaluate(() => window.__meshmorph.state.error);
  if (error) throw new Error(`${label}: ${error.code} ${error.message}`);
  await page.evaluate(() => window.__meshmorph.nextFrame());
  const arrow = await page.evaluate(() => window.__meshmorph.hooks.editGizmoHandle('Y'));
  await page.mouse.move(arrow.x, arrow.y);
  await page.mouse.down();
  const before = await page.evaluate(() => ({ t: performance.now(), frames: window.__meshmorph.frames, answered: window.__meshmorph.state.edit.drags.answered }));
  const until = Date.now() + seconds * 1000;
  for (let i = 1; Date.now() < until; ++i) await page.mouse.move(arrow.x, arrow.y - (i % 120));
  const after = await page.evaluate(() => ({ t: performance.now(), frames: window.__meshmorph.frames, answered: window.__meshmorph.state.edit.drags.answered }));
  await page.mouse.up();
  await page.waitForFunction(() => !window.__meshmorph.state.busy, null, { timeout: 60000 });
  const longest = await page.evaluate(({ a, b }) => window.__longTasks.filter((t) => t.start < b && t.start + t.duration > a).reduce((m, t) => Math.max(m, t.duration), 0), { a: before.t, b: after.t });
  const s = (after.t - before.t) / 1000;
  const vertices = await page.evaluate(() => window.__meshmorph.state.mesh.weldedVertices);
  console.log(`${label} (${vertices} vertices): ${((after.frames - before.frames) / s).toFixed(1)} frames/s, `
    + `${((after.answered - before.answered) / s).toFixed(1)} editDrag answers/s, longest main-thread task ${longest.toFixed(0)} ms `
    + `(${s.toFixed(1)} s drag, load average ${os.loadavg()[0].toFixed(1)} on ${os.cpus().length} cores)`);
  await page.click('#edit-stop');
}

async function main() {
  fs.mkdirSync(outDir, { recursive: true });
  const big = path.join(outDir, 'armadillo-58k.ply');
  if (!fs.existsSync(big)) fs.writeFileSync(big, binaryPly(subdivide(readBinaryPly(fs.readFileSync(path.join(repoDir, 'data/edit/armadillo.ply'))), 2)));
  const server = await preview({ configFile: path.join(repoDir, 'web/vite.config.js'), logLevel: 'warn', preview: { host: '127.0.0.1', port: 0, open: false } });
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'meshmorph-bench-'));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: process.env.MM_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1280, height: 800 },
    args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--ignore-gpu-blocklist', '--disable-dev-shm-usage'],
  });
  try {
    await context.addInitScript(() => {
      window.__longTasks = [];
      new PerformanceObserver((list) => { for (const e of list.getEntries()) window.__longTasks.push({ start: e.startTime, duration: e.duration }); })
        .observe({ type: 'longtask', buffered: true });
    });
    const page = context.pages()[0] || (await context.newPage());
    const { port } = server.httpServer.address();
    await page.goto(`http://127.0.0.1:${port}/`);
    await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1 && !window.__meshmorph.state.busy, null, { timeout: 60000 });
    await bench(page, path.join(repoDir, 'data/edit/armadillo.ply'), 'armadillo');
    await bench(page, big, 'armadillo ×4');
  } finally {
    await context.close();
    await new Promise((resolve) => server.httpServer.close(resolve));
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
}

main();
