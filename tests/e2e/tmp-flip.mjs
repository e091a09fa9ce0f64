// Temporary (twenty-third session): michael9 (../shared) → armadillo in the page, Chromium and Firefox,
// to see the flip repair row. Deleted after use.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { preview } from 'vite';
import { runInFirefox } from './firefox.mjs';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const configFile = path.join(repoDir, 'web/vite.config.js');
const shotDir = '/tmp/flip-page';
fs.mkdirSync(shotDir, { recursive: true });

async function flow({ page }, tag) {
  await page.waitForFunction(() => window.__meshmorph?.state.ready && !window.__meshmorph.state.busy, null, { timeout: 90000 });
  await page.click('#jobs button[data-job="transfer"]');
  await page.setInputFiles('#tr-reference-file', path.join(repoDir, '../shared/data/pose/tosca/michael9.off'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.reference?.name === 'michael9.off' || window.__meshmorph.state.error, null, { timeout: 90000 });
  await page.waitForFunction(() => !window.__meshmorph.state.busy, null, { timeout: 90000 });
  await page.setInputFiles('#tr-source-file', path.join(repoDir, 'data/edit/armadillo.ply'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.source?.name === 'armadillo.ply' || window.__meshmorph.state.error, null, { timeout: 90000 });
  await page.waitForFunction(() => !window.__meshmorph.state.busy, null, { timeout: 90000 });
  await page.setInputFiles('#tr-landmarks-load', path.join(repoDir, 'data/landmarks/michael3-armadillo.json'));
  await page.waitForFunction(() => window.__meshmorph.state.transfer.pairs.length > 0 || window.__meshmorph.state.error, null, { timeout: 10000 });
  const t0 = Date.now();
  await page.click('#tr-run');
  await page.waitForFunction(() => window.__meshmorph.state.transfer.runs >= 1 || window.__meshmorph.state.error, null, { timeout: 300000 });
  await page.waitForFunction(() => !window.__meshmorph.state.busy, null, { timeout: 300000 });
  const ms = Date.now() - t0;
  const err = await page.evaluate(() => window.__meshmorph.state.error);
  const metrics = await page.textContent('#tr-metrics');
  console.log(`${tag}: ${ms} ms, error ${JSON.stringify(err)}\n${metrics}`);
  await page.locator('#tr-metrics').scrollIntoViewIfNeeded();
  await page.screenshot({ path: path.join(shotDir, `${tag}.png`) });
}

const server = await preview({ configFile, logLevel: 'warn', preview: { host: '127.0.0.1', port: 5191, strictPort: true, open: false } });
const baseUrl = 'http://127.0.0.1:5191/';
const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'mm-flip-'));
try {
  if (!process.argv.includes('--firefox-only')) {
    const context = await chromium.launchPersistentContext(userDataDir, {
      executablePath: '/usr/bin/chromium', headless: true, viewport: { width: 1280, height: 800 },
      args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--ignore-gpu-blocklist'],
    });
    const page = context.pages()[0] || (await context.newPage());
    await page.goto(baseUrl);
    await flow({ page }, 'chromium');
    await context.close();
  }
  const ff = await runInFirefox({ tests: [{ name: 'flip', fn: (ctx) => flow(ctx, 'firefox') }], baseUrl, initScripts: [], shotDir });
  console.log('firefox', ff.passed, ff.failed);
} finally {
  server.httpServer.close();
  fs.rmSync(userDataDir, { recursive: true, force: true });
}
