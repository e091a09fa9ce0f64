// Retarget playback bench (issue 17's figure, reported, not asserted): in headless Chromium, the
// Retarget job plays a KayKit clip retargeted onto the bundled human woman (6 890 vertices, the
// "7k-vertex character") while the worker is still computing further frames: a long clip
// (Knight's Sit_Floor_Idle, 4 s) sampled at a high rate (fps option, default 120 → 480 frames)
// keeps the worker busy. Prints the time from choosing the clip to its first shown frame, the
// rendered frames per second of the view and the target updates per second while frames are
// computing and after the last one arrived, and the longest main-thread task in each window.
// Then, playback paused, the renderer's own ceiling on this machine: the view redrawn in a
// requestAnimationFrame loop with nothing else to do (the same scene; then only the target
// surface, opaque: one lit 7k-vertex mesh), so a low playback rate can be told apart from the
// page's own per-frame work (on a GPU-less machine Chromium renders WebGL with SwiftShader).
// Needs the built page (node tests/e2e/run.mjs builds it; or `npm run build:web`).
// Usage: MM_WASM_DIR=… node tests/e2e/retarget-bench.mjs [fps = 120] [seconds after = 3]
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { preview } from 'vite';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const fps = Number(process.argv[2] || 120);
const secondsAfter = Number(process.argv[3] || 3);

const sample = (page) => page.evaluate(() => ({
  t: performance.now(), frames: window.__meshmorph.frames, shown: window.__meshmorph.state.retarget.shownFrames,
  status: window.__meshmorph.state.retarget.run.status, received: window.__meshmorph.state.retarget.run.received ?? 0,
}));

async function longest(page, a, b) {
  return page.evaluate(({ from, to }) => window.__longTasks.filter((t) => t.start < to && t.start + t.duration > from).reduce((m, t) => Math.max(m, t.duration), 0), { from: a, to: b });
}

function rates(a, b) {
  const s = (b.t - a.t) / 1000;
  return { seconds: s, fps: (b.frames - a.frames) / s, updates: (b.shown - a.shown) / s, frames: b.received - a.received };
}

async function main() {
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
      // Which scripts made the slow frames (long-animation-frame, Chromium).
      window.__longFrames = [];
      new PerformanceObserver((list) => {
        for (const e of list.getEntries()) {
          window.__longFrames.push({ start: e.startTime, duration: e.duration, blocking: e.blockingDuration,
            scripts: e.scripts.map((x) => `${x.invoker} ${x.sourceFunctionName || ''}:${x.sourceCharPosition} ${x.duration.toFixed(0)}ms`) });
        }
      }).observe({ type: 'long-animation-frame', buffered: true });
    });
    const page = context.pages()[0] || (await context.newPage());
    const { port } = server.httpServer.address();
    await page.goto(`http://127.0.0.1:${port}/`);
    await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1 && !window.__meshmorph.state.busy, null, { timeout: 60000 });
    await page.click('#jobs button[data-job="retarget"]');
    await page.waitForFunction(() => document.querySelector('section.retarget .lil-gui.options'), null, { timeout: 30000 });
    await page.selectOption('#rt-character', 'knight');
    await page.waitForFunction(() => document.querySelectorAll('#rt-clip option').length > 0, null, { timeout: 60000 });
    await page.selectOption('#rt-target', 'woman');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.joints > 0 && !window.__meshmorph.state.busy, null, { timeout: 60000 });
    await page.click('section.retarget .lil-gui.options > .lil-title');
    await page.fill('#opt-fps', String(fps));
    await page.click('section.retarget h2');
    await page.fill('#rt-clip-filter', 'Sit_Floor_Idle');
    const value = await page.evaluate(() => document.querySelector('#rt-clip option').value);
    await page.selectOption('#rt-clip', value);
    await page.waitForFunction(() => window.__meshmorph.state.retarget.shownFrames > 0 || window.__meshmorph.state.retarget.run.status === 'error', null, { timeout: 180000 });
    const first = await sample(page);
    if (first.status === 'error') throw new Error(JSON.stringify(await page.evaluate(() => window.__meshmorph.state.retarget.run.error)));
    const state = await page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.retarget)));
    const vertices = state.target.vertices;
    // While computing: sample until the last frame arrives.
    await page.waitForFunction(() => window.__meshmorph.state.retarget.run.status !== 'frames', null, { timeout: 600000 });
    const done = await sample(page);
    const during = rates(first, done);
    const longDuring = await longest(page, first.t, done.t);
    await page.waitForTimeout(secondsAfter * 1000);
    const end = await sample(page);
    const after = rates(done, end);
    const longAfter = await longest(page, done.t, end.t);
    // The renderer's ceiling: playback paused, the view redrawn back to back for 2 s.
    await page.click('#rt-play');
    await page.waitForFunction(() => !window.__meshmorph.state.retarget.playing, null, { timeout: 5000 });
    const renderLoop = (onlySurface) => page.evaluate(async (only) => {
      const v = window.__meshmorph.viewer;
      const hidden = [];
      let surface = null;
      v.scene.traverse((o) => { if (o.name === 'retarget-target-surface') surface = o; });
      const saved = { transparent: surface.material.transparent, opacity: surface.material.opacity, depthWrite: surface.material.depthWrite };
      if (only) {
        v.scene.traverse((o) => { if ((o.isMesh || o.isLine || o.isPoints) && o !== surface && o.visible) { o.visible = false; hidden.push(o); } });
        Object.assign(surface.material, { transparent: false, opacity: 1, depthWrite: true });
        surface.material.needsUpdate = true;
      }
      v.render();
      const t0 = performance.now();
      let n = 0;
      await new Promise((resolve) => {
        const step = () => { v.render(); n += 1; if (performance.now() - t0 < 2000) requestAnimationFrame(step); else resolve(); };
        requestAnimationFrame(step);
      });
      const fps = (n * 1000) / (performance.now() - t0);
      for (const o of hidden) o.visible = true;
      Object.assign(surface.material, saved);
      surface.material.needsUpdate = true;
      return fps;
    }, onlySurface);
    const sceneLoop = await renderLoop(false);
    const surfaceLoop = await renderLoop(true);
    const size = await page.evaluate(() => window.__meshmorph.viewer.size);
    const load = `load average ${os.loadavg()[0].toFixed(1)} on ${os.cpus().length} cores`;
    console.log(`Knight Sit_Floor_Idle → human_woman (${vertices} vertices), ${state.run.frames} frames at ${fps} fps; clip chosen → first frame shown ${state.firstFrameMs} ms (prepare ${state.run.prepareMs} ms)`);
    console.log(`  while computing (${during.seconds.toFixed(1)} s, ${during.frames} frames arrived): ${during.fps.toFixed(1)} rendered frames/s, ${during.updates.toFixed(1)} target updates/s, longest main-thread task ${longDuring.toFixed(0)} ms`);
    const slow = await page.evaluate(({ from, to }) => window.__longFrames.filter((f) => f.start >= from && f.start <= to).sort((a, b) => b.duration - a.duration).slice(0, 3), { from: first.t - 15000, to: done.t });
    for (const f of slow) console.log(`  slow frame ${f.duration.toFixed(0)} ms (blocking ${f.blocking.toFixed(0)} ms): ${f.scripts.join(' | ') || 'no script (rendering / the GPU process)'}`);
    console.log(`  after the last frame (${after.seconds.toFixed(1)} s): ${after.fps.toFixed(1)} rendered frames/s, ${after.updates.toFixed(1)} target updates/s, longest main-thread task ${longAfter.toFixed(0)} ms (${load})`);
    console.log(`  the renderer alone (paused, redrawn back to back, ${size.width}×${size.height} px, 4× MSAA): the same scene ${sceneLoop.toFixed(1)} frames/s; only the target surface, opaque (one lit ${vertices}-vertex mesh) ${surfaceLoop.toFixed(1)} frames/s`);
  } finally {
    await context.close();
    await new Promise((resolve) => server.httpServer.close(resolve));
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
}

main();
