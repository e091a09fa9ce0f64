// The end-to-end tests in Firefox ESR (Debian's firefox-esr) through puppeteer-core over
// WebDriver BiDi. Firefox's headless mode gets no WebGL context on this machine, so it runs
// headed on a private Xvfb display that this module starts and stops (../shared/TOOLCHAIN.md
// §3b). The tests are the same functions as in Chromium (run.mjs): PlaywrightLikePage below
// gives them the small part of playwright's Page API they use, on top of puppeteer's.
//
// Differences handled here: downloads are captured in the page (an anchor with `download`
// records its name and blob instead of opening Firefox's download flow); file inputs take
// uploadFile(); buttons are clicked through the DOM (the canvas gets real pointer events from
// page.mouse); console type 'warn' is playwright's 'warning'; no long-task observer (Firefox
// has no 'longtask' entries), so those figures are Chromium's only.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

export const firefoxPath = process.env.MM_FIREFOX || '/usr/bin/firefox-esr';
const xvfbPath = '/usr/bin/Xvfb';

// Why Firefox cannot run here, or null when it can.
export function firefoxMissing() {
  if (!fs.existsSync(firefoxPath)) return `${firefoxPath} not found (apt-get install firefox-esr, or set MM_FIREFOX)`;
  if (!process.env.DISPLAY && !fs.existsSync(xvfbPath)) return `no DISPLAY and no ${xvfbPath} (apt-get install xvfb)`;
  return null;
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// A free X display number: the first :N without a lock file.
function freeDisplay() {
  for (let n = 90; n < 190; ++n) if (!fs.existsSync(`/tmp/.X${n}-lock`) && !fs.existsSync(`/tmp/.X11-unix/X${n}`)) return n;
  throw new Error('no free X display number');
}

async function startXvfb() {
  if (process.env.DISPLAY) return { display: process.env.DISPLAY, stop: () => {} };
  const n = freeDisplay();
  const child = spawn(xvfbPath, [`:${n}`, '-screen', '0', '1280x900x24', '-nolisten', 'tcp'], { stdio: 'ignore' });
  for (let i = 0; i < 100 && !fs.existsSync(`/tmp/.X11-unix/X${n}`); ++i) await sleep(50);
  return { display: `:${n}`, stop: () => child.kill() };
}

// Installed before the page's scripts: downloads are recorded, not performed.
function captureDownloads() {
  window.__downloads = [];
  const click = HTMLAnchorElement.prototype.click;
  HTMLAnchorElement.prototype.click = function clickOrRecord() {
    if (this.download && this.href.startsWith('blob:')) {
      window.__downloads.push({ name: this.download, url: this.href });
      return;
    }
    click.call(this);
  };
}

class Locator {
  constructor(page, selector) {
    this.page = page;
    this.selector = selector;
  }

  count() { return this.page.evaluate((s) => document.querySelectorAll(s).length, this.selector); }

  first() { return new Locator(this.page, this.selector); }

  getAttribute(name) { return this.page.evaluate((s, n) => document.querySelector(s)?.getAttribute(n) ?? null, this.selector, name); }

  scrollIntoViewIfNeeded() { return this.page.evaluate((s) => document.querySelector(s)?.scrollIntoView({ block: 'nearest' }), this.selector); }

  async boundingBox() {
    const handle = await this.page.$(this.selector);
    return handle.boundingBox();
  }
}

// The subset of playwright's Page that tests/e2e/run.mjs uses.
export class PlaywrightLikePage {
  constructor(page, { shotPrefix }) {
    this.page = page;
    this.shotPrefix = shotPrefix;
    this.mouse = page.mouse;
    this.keyboard = page.keyboard;
    this.tempDir = fs.mkdtempSync(path.join(os.tmpdir(), 'meshmorph-ff-'));
  }

  evaluate(fn, arg) { return this.page.evaluate(fn, arg); }

  evaluateHandle(fn, arg) { return this.page.evaluateHandle(fn, arg); }

  waitForFunction(fn, arg, { timeout = 30000 } = {}) { return this.page.waitForFunction(fn, { timeout, polling: 100 }, arg); }

  waitForTimeout(ms) { return sleep(ms); }

  waitForSelector(selector, { state = 'visible', timeout = 30000 } = {}) {
    return this.page.waitForSelector(selector, { visible: state === 'visible', hidden: state === 'hidden', timeout });
  }

  // A DOM click on the element (scrolled into view): the side panel scrolls, and pointer
  // clicks at computed positions are what the canvas tests use page.mouse for.
  async click(selector) {
    await this.page.waitForSelector(selector, { timeout: 30000 });
    await this.page.evaluate((s) => {
      const el = document.querySelector(s);
      el.scrollIntoView({ block: 'nearest' });
      el.click();
    }, selector);
  }

  selectOption(selector, value) { return this.page.select(selector, value); }

  // The focus and blur events are dispatched as well: under Xvfb the window does not always have
  // the focus, and then focus()/blur() fire nothing (lil-gui's finish-change listens to blur).
  async press(selector, key) {
    await this.page.focus(selector);
    await this.page.keyboard.press(key);
  }

  fill(selector, value) {
    return this.page.evaluate((s, v) => {
      const input = document.querySelector(s);
      input.focus();
      input.dispatchEvent(new FocusEvent('focus'));
      input.value = v;
      input.dispatchEvent(new Event('input', { bubbles: true }));
      input.dispatchEvent(new Event('change', { bubbles: true }));
      input.dispatchEvent(new FocusEvent('blur'));
      input.blur();
    }, selector, value);
  }

  inputValue(selector) { return this.page.evaluate((s) => document.querySelector(s).value, selector); }

  async setChecked(selector, on) {
    const checked = await this.isChecked(selector);
    if (checked !== on) await this.page.evaluate((s) => document.querySelector(s).click(), selector);
  }

  check(selector) { return this.setChecked(selector, true); }

  uncheck(selector) { return this.setChecked(selector, false); }

  isChecked(selector) { return this.page.evaluate((s) => document.querySelector(s).checked, selector); }

  isEnabled(selector) { return this.page.evaluate((s) => !document.querySelector(s).disabled, selector); }

  isDisabled(selector) { return this.page.evaluate((s) => document.querySelector(s).disabled, selector); }

  isVisible(selector) {
    return this.page.evaluate((s) => {
      const el = document.querySelector(s);
      if (!el) return false;
      const rect = el.getBoundingClientRect();
      return rect.width > 0 && rect.height > 0 && getComputedStyle(el).visibility !== 'hidden';
    }, selector);
  }

  textContent(selector) { return this.page.evaluate((s) => document.querySelector(s)?.textContent ?? null, selector); }

  getAttribute(selector, name) { return this.page.evaluate((s, n) => document.querySelector(s)?.getAttribute(n) ?? null, selector, name); }

  locator(selector) { return new Locator(this.page, selector); }

  // files: a path, paths, or {name, mimeType, buffer} objects (written to temporary files).
  async setInputFiles(selector, files) {
    const list = (Array.isArray(files) ? files : [files]).map((f) => {
      if (typeof f === 'string') return f;
      const file = path.join(fs.mkdtempSync(path.join(this.tempDir, 'f')), f.name);
      fs.writeFileSync(file, f.buffer);
      return file;
    });
    const input = await this.page.$(selector);
    await input.uploadFile(...list);
  }

  async waitForEvent(type, { timeout = 30000 } = {}) {
    if (type !== 'download') throw new Error(`waitForEvent('${type}') is not supported in the Firefox run`);
    const before = await this.page.evaluate(() => window.__downloads.length);
    await this.page.waitForFunction((n) => window.__downloads.length > n, { timeout, polling: 50 }, before);
    const { name, url } = await this.page.evaluate((n) => window.__downloads[n], before);
    const base64 = await this.page.evaluate(async (u) => {
      const bytes = new Uint8Array(await (await fetch(u)).arrayBuffer());
      let text = '';
      for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
      return btoa(text);
    }, url);
    return { suggestedFilename: () => name, saveAs: async (file) => fs.writeFileSync(file, Buffer.from(base64, 'base64')) };
  }

  screenshot({ path: file }) {
    return this.page.screenshot({ path: path.join(path.dirname(file), `${this.shotPrefix}${path.basename(file)}`) });
  }

  setViewportSize({ width, height }) { return this.page.setViewport({ width, height }); }

  close() { return this.page.close(); }
}

// Resolves with the promise's value, or with `fallback` after ms (a wedged browser must not hang us).
const within = (promise, ms, fallback) => Promise.race([promise, sleep(ms).then(() => fallback)]);

// What the page shows when it is not ready: enough to tell a slow start from a wedged one.
async function startupState(raw) {
  return within(raw.evaluate(() => ({
    readyState: document.readyState,
    isolated: window.crossOriginIsolated,
    app: Boolean(window.__meshmorph),
    status: document.getElementById('status')?.textContent ?? null,
    error: window.__meshmorph?.state.error ?? null,
  })).then((s) => JSON.stringify(s), (e) => `evaluate failed: ${e.message}`), 10000, 'the page did not answer in 10 s');
}

// One Firefox on its own Xvfb with the page loaded and its worker ready, or an error saying what
// the page showed. Callers close it with close().
// pageErrors and consoleSink.lines receive the page's errors and console errors/warnings.
async function openFirefox({ baseUrl, initScripts, readyTimeout, pageErrors, consoleSink }) {
  const { launch } = await import('puppeteer-core');
  const xvfb = await startXvfb();
  let browser = null;
  const close = async () => {
    await within(browser?.close().catch(() => {}) ?? Promise.resolve(), 15000);
    browser?.process()?.kill('SIGKILL');
    xvfb.stop();
  };
  try {
    browser = await launch({
      browser: 'firefox',
      executablePath: firefoxPath,
      headless: false,
      defaultViewport: { width: 1280, height: 800 },
      env: { ...process.env, DISPLAY: xvfb.display, MOZ_ENABLE_WAYLAND: '0' },
      extraPrefsFirefox: { 'browser.download.useDownloadDir': true, 'browser.download.always_ask_before_handling_new_types': false },
    });
    const raw = await browser.newPage();
    for (const script of [captureDownloads, ...initScripts]) await raw.evaluateOnNewDocument(script);
    // Listening from before the page loads: errors while it starts count too.
    raw.on('pageerror', (e) => pageErrors.push(e.message));
    raw.on('console', (m) => {
      const type = m.type() === 'warn' ? 'warning' : m.type();
      if (type === 'error' || type === 'warning') consoleSink.lines.push(`[firefox ${type}] ${m.text()}`);
    });
    await raw.goto(baseUrl);
    try {
      await raw.waitForFunction(() => window.__meshmorph?.state.ready || window.__meshmorph?.state.error, { timeout: readyTimeout, polling: 200 });
    } catch (e) {
      throw new Error(`the page was not ready after ${readyTimeout / 1000} s: ${await startupState(raw)}; console: ${consoleSink.lines.join(' | ') || 'nothing'}`);
    }
    return { browser, raw, close };
  } catch (e) {
    await close();
    throw e;
  }
}

// Runs `tests` ([{name, fn}]) in Firefox against baseUrl. `extra` are added to each test's
// arguments. Returns {passed, failed, version}; prints one line per test like run.mjs.
// A Firefox whose page never gets ready (seen once in CI: every wait timed out, no console
// line) is started again once, with what the page showed printed; a second failure fails
// every test at once instead of waiting a minute in each.
export async function runInFirefox({ tests, baseUrl, initScripts, shotDir, shotPrefix = 'firefox-', log = console.log }) {
  let session = null;
  const pageErrors = [];
  const consoleSink = { lines: [] };
  let passed = 0;
  let failed = 0;
  let version = '';
  for (let attempt = 1; attempt <= 2 && !session; ++attempt) {
    try {
      pageErrors.length = 0;
      consoleSink.lines = [];
      session = await openFirefox({ baseUrl, initScripts, readyTimeout: 90000, pageErrors, consoleSink });
    } catch (e) {
      log(`note [firefox] start ${attempt} of 2 failed: ${String(e.message || e).split('\n')[0]}`);
    }
  }
  if (!session) {
    for (const t of tests) log(`FAIL [firefox] ${t.name} (Firefox did not start the page twice; see the notes above)`);
    return { passed: 0, failed: tests.length, version: 'not started' };
  }
  const { browser, raw, close } = session;
  try {
    version = await browser.version();
    const page = new PlaywrightLikePage(raw, { shotPrefix });
    const allConsole = [];
    for (const t of tests) {
      const started = Date.now();
      // The first test also sees what the page printed while it started.
      if (t !== tests[0]) consoleSink.lines = [];
      const consoleLines = consoleSink.lines;
      try {
        await t.fn({ page, context: null, baseUrl, pageErrors, allConsole, consoleLines, browser: 'firefox' });
        allConsole.push(...consoleLines.map((l) => `${t.name}: ${l}`));
        passed += 1;
        log(`ok   [firefox] ${t.name} (${Date.now() - started} ms)`);
      } catch (e) {
        allConsole.push(...consoleLines.map((l) => `${t.name}: ${l}`));
        failed += 1;
        log(`FAIL [firefox] ${t.name} (${Date.now() - started} ms)\n     ${String(e.message || e).split('\n').join('\n     ')}`);
        for (const line of consoleLines) log(`     ${line}`);
        await page.screenshot({ path: path.join(shotDir, `fail-${tests.indexOf(t)}.png`) }).catch(() => {});
      }
    }
  } finally {
    await close();
  }
  return { passed, failed, version };
}
