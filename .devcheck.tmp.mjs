import { createServer } from 'vite';
import { chromium } from 'playwright-core';
import fs from 'node:fs'; import os from 'node:os'; import path from 'node:path';
const server = await createServer({ configFile: '/work/main/web/vite.config.js', logLevel: 'warn', server: { host: '127.0.0.1', port: 5199, strictPort: true } });
await server.listen();
const ctx = await chromium.launchPersistentContext(fs.mkdtempSync(path.join(os.tmpdir(), 'mmdev-')), { executablePath: '/usr/bin/chromium', headless: true, args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader'] });
const page = ctx.pages()[0];
page.on('console', (m) => console.log('page:', m.type(), m.text()));
page.on('pageerror', (e) => console.log('pageerror', e.message));
await page.goto('http://127.0.0.1:5199/');
try {
  await page.waitForFunction(() => window.__meshmorph?.state.loads >= 1, null, { timeout: 60000 });
  console.log('dev ok', await page.evaluate(() => [window.__meshmorph.cancelMode, window.__meshmorph.state.mesh.name]));
} catch (e) { console.log('dev FAIL', e.message); }
await ctx.close(); await server.close();
