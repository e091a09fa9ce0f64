// End-to-end tests of the Retarget job (web/src/ui/panels/retarget.js), registered by
// tests/e2e/run.mjs (`registerRetargetTests(it, helpers)`): a KayKit clip from the page's clip
// library (with its preview) onto the rigged Barbarian (joints from its skin) and onto the
// bundled human woman (joints from her file for KayKit's skeleton); frames computed in batches
// and played while they arrive, the timeline played, paused and scrubbed with the real mouse;
// one frame compared with `meshmorph retarget` (MM_CLI) on the same inputs; harmonic vs LBS;
// an option change that recomputes (the run going is cancelled); the GLB downloaded, validated
// (gltf-validator) and played again in the page; the joints JSON downloaded; errors shown.
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';

// The vertices of an OBJ file the CLI wrote (17 significant digits).
function readObjVertices(text) {
  const out = [];
  for (const line of text.split('\n')) {
    if (line.startsWith('v ')) {
      const [, x, y, z] = line.trim().split(/\s+/);
      out.push(Number(x), Number(y), Number(z));
    }
  }
  return out;
}

function heightOf(p) {
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = 1; i < p.length; i += 3) { lo = Math.min(lo, p[i]); hi = Math.max(hi, p[i]); }
  return hi - lo;
}

export function registerRetargetTests(it, { check, shot, nextFrame, waitIdle, canvasPixels, pixelStats, repoDir, shotDir, cliPath, record }) {
  const rtState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.retarget)));

  function cli(args, label) {
    check(fs.existsSync(cliPath), `the CLI is missing: ${cliPath} (set MM_CLI)`);
    const run = spawnSync(cliPath, args, { encoding: 'utf8', timeout: 300000 });
    check(run.status === 0, `meshmorph ${label} failed (${run.status}): ${run.stderr}${run.stdout}`);
    return run.stdout;
  }

  // The CLI's frame k (target surface) for the same inputs, as an OBJ. Computed once per run:
  // the Firefox pass compares its page with the same CLI output as the Chromium pass.
  const cliFrames = new Map();
  function cliFrame(args, k, name) {
    // Files the test wrote (a pins JSON from this browser's drag) count by their contents.
    const key = JSON.stringify([args.map((a) => (a.startsWith(shotDir) && fs.existsSync(a) ? fs.readFileSync(a, 'utf8') : a)), k]);
    if (!cliFrames.has(key)) {
      const out = path.join(shotDir, `${name}.obj`);
      cli(['retarget', ...args, '--out', out, '--frames', `${k}:${k + 1}`], 'retarget');
      cliFrames.set(key, readObjVertices(fs.readFileSync(out.replace(/\.obj$/, '_0000.obj'), 'utf8')));
    }
    return cliFrames.get(key);
  }

  async function download(page, selector) {
    const [file] = await Promise.all([page.waitForEvent('download', { timeout: 60000 }), page.click(selector)]);
    const to = path.join(shotDir, file.suggestedFilename());
    await file.saveAs(to);
    return to;
  }

  async function openJob(page) {
    await page.click('#jobs button[data-job="retarget"]');
    await page.waitForSelector('#rt-character', { state: 'visible' });
    await waitIdle(page);
    await page.waitForFunction(() => document.querySelector('section.retarget .lil-gui.options'), null, { timeout: 30000 });
  }

  async function chooseCharacter(page, id) {
    await page.selectOption('#rt-character', id);
    await page.waitForFunction((i) => window.__meshmorph.state.retarget.source?.id === i && document.querySelectorAll('#rt-clip option').length > 0, id, { timeout: 60000 });
  }

  async function chooseTarget(page, id, { joints = true } = {}) {
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.selectOption('#rt-target', id);
    await page.waitForFunction((i) => window.__meshmorph.state.retarget.target?.id === i || window.__meshmorph.state.error, id, { timeout: 60000 });
    await waitIdle(page);
    if (joints) await page.waitForFunction(() => window.__meshmorph.state.retarget.joints > 0 || window.__meshmorph.state.error, null, { timeout: 30000 });
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(!error, `target ${id}: ${JSON.stringify(error)}`);
  }

  // Filters the clip list by typing, then clicks the clip in the list (the real mouse).
  async function chooseClip(page, name) {
    await page.fill('#rt-clip-filter', name);
    const value = await page.evaluate((n) => [...document.querySelectorAll('#rt-clip option')].find((o) => o.textContent.startsWith(`${n} `))?.value, name);
    check(value != null, `clip ${name} not in the filtered list`);
    await page.selectOption('#rt-clip', value);
  }

  async function waitRun(page, timeout = 180000) {
    await page.waitForFunction(() => ['done', 'error'].includes(window.__meshmorph.state.retarget.run.status), null, { timeout });
    const s = await rtState(page);
    check(s.run.status === 'done', `the run failed: ${JSON.stringify(s.run.error)}`);
    return s;
  }

  function compareFrame(pageFrame, cliFrameValues, label) {
    check(pageFrame && pageFrame.length === cliFrameValues.length, `${label}: page frame has ${pageFrame?.length} values, CLI ${cliFrameValues.length}`);
    let max = 0;
    for (let i = 0; i < pageFrame.length; ++i) max = Math.max(max, Math.abs(pageFrame[i] - cliFrameValues[i]));
    const rel = max / heightOf(cliFrameValues);
    return rel;
  }

  it('retarget: KayKit Knight clip from the library onto the rigged Barbarian — preview, frames in batches, play, scrub, the CLI\'s frame, harmonic vs LBS, GLB validated and played again', async ({ page, browser, pageErrors }) => {
    await openJob(page);
    await shot(page, 'retarget-0-job');
    await chooseCharacter(page, 'knight');
    const s0 = await rtState(page);
    check(s0.source.clips.length === 76, `Knight clips: ${s0.source.clips.length}`);
    check(s0.step === 0, `step ${s0.step}`);
    await shot(page, 'retarget-1-library');

    // The target first (its joints from the skin, see-through), then the clip: the run starts
    // when the clip is chosen, so the time to the first frame is the clip's.
    await chooseTarget(page, 'barbarian');
    const s1 = await rtState(page);
    check(s1.target.skinned && s1.jointsFrom === 'skin' && s1.joints >= 20, `Barbarian joints: ${JSON.stringify({ skinned: s1.target.skinned, from: s1.jointsFrom, n: s1.joints })}`);
    await nextFrame(page);
    await shot(page, 'retarget-2-target-joints');

    await chooseClip(page, 'Walking_A');
    // The preview plays (its own canvas draws frames).
    const previewFrames = await page.evaluate(() => window.__meshmorph.hooks.retargetPreviewFrames());
    await page.waitForFunction((n) => window.__meshmorph.hooks.retargetPreviewFrames() > n + 3, previewFrames, { timeout: 10000 });
    // The first frames play before the last ones are computed.
    await page.waitForFunction(() => window.__meshmorph.state.retarget.shownFrames > 0, null, { timeout: 120000 });
    const early = await rtState(page);
    await shot(page, 'retarget-3-first-frames');
    const s2 = await waitRun(page);
    check(s2.firstFrameMs > 0, 'no first-frame time');
    check(early.run.received < s2.run.frames || early.run.status === 'done', 'frames did not arrive in batches');
    record(browser, 'retarget Knight → Barbarian: clip chosen → first frame shown (ms)', s2.firstFrameMs);
    record(browser, 'retarget Knight → Barbarian: prepare (ms)', s2.run.prepareMs);
    check(s2.run.clip === 'Walking_A' && s2.run.frames >= 20, `run: ${JSON.stringify(s2.run)}`);
    check(s2.playing, 'playback did not start when the frames arrived');
    // Playing: the time moves and the shown surface changes.
    // Waited for, not slept on: on a loaded 2-core CI machine a headless page can go 400 ms
    // without an animation frame (the twenty-third submission's CI failed here).
    const t0 = s2.time;
    const moved = await page.waitForFunction((t) => window.__meshmorph.state.retarget.time !== t, t0, { timeout: 10000 })
      .then(() => true, () => false);
    check(moved, 'the clip time did not move while playing (10 s)');
    await shot(page, 'retarget-4-playing');

    // Pause, then scrub with the mouse to 3/4 of the bar.
    await page.click('#rt-play');
    const paused = await rtState(page);
    check(!paused.playing, 'pause did not pause');
    const bar = await page.evaluate(() => window.__meshmorph.hooks.retargetScrubRect());
    await page.mouse.click(bar.left + bar.width * 0.75, bar.top + bar.height / 2);
    await nextFrame(page);
    const scrubbed = await rtState(page);
    const expected = bar.min + 0.75 * (bar.max - bar.min);
    check(Math.abs(scrubbed.time - expected) < 0.06 * (bar.max - bar.min), `scrub: time ${scrubbed.time}, expected ≈ ${expected}`);
    await shot(page, 'retarget-5-scrubbed');

    // The shown surface at a frame's own time is that frame; frame 10 against the CLI.
    const times = await page.evaluate(() => window.__meshmorph.hooks.retargetTimes());
    const k = 10;
    await page.evaluate((t) => window.__meshmorph.hooks.retargetSeek(t), times[k]);
    const shown = await page.evaluate(() => window.__meshmorph.hooks.retargetShown());
    const pageFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    check(shown.every((v, i) => Math.abs(v - pageFrame[i]) < 1e-6), 'the shown surface is not frame 10 at its time');
    const args = ['--source', path.join(repoDir, 'data/anim/KayKit/Knight.glb'), '--clip', 'Walking_A', '--target', path.join(repoDir, 'data/anim/KayKit/Barbarian.glb')];
    const rel = compareFrame(pageFrame, cliFrame(args, k, 'retarget-cli-knight-barbarian'), 'Knight → Barbarian');
    record(browser, 'retarget Knight → Barbarian frame 10: page vs CLI (max / height)', rel.toExponential(2));
    check(rel < 1e-4, `frame ${k} differs from the CLI's by ${rel} of the height`);

    // The LBS baseline: a new run (the harmonic one is replaced), other frames, also the CLI's.
    await page.click('input[name="rt-method"][value="lbs"]');
    const lbs = await waitRun(page);
    check(lbs.run.options.method === 'lbs', `method ${lbs.run.options.method}`);
    const lbsFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    const relLbs = compareFrame(lbsFrame, cliFrame([...args, '--method', 'lbs'], k, 'retarget-cli-knight-barbarian-lbs'), 'LBS');
    check(relLbs < 1e-4, `LBS frame ${k} differs from the CLI's by ${relLbs}`);
    let differ = 0;
    for (let i = 0; i < lbsFrame.length; ++i) differ = Math.max(differ, Math.abs(lbsFrame[i] - pageFrame[i]));
    check(differ > 1e-3, 'harmonic and LBS frames are the same');
    await page.evaluate((t) => window.__meshmorph.hooks.retargetSeek(t), times[k]);
    await nextFrame(page);
    await shot(page, 'retarget-6-lbs');
    await page.click('input[name="rt-method"][value="harmonic"]');
    await waitRun(page);

    // Split panes.
    await page.click('input[name="rt-view"][value="split"]');
    await nextFrame(page);
    await shot(page, 'retarget-7-split');
    const split = pixelStats(await canvasPixels(page));
    check(split.foreground > 0.02, `split view nearly empty (${split.foreground})`);
    await page.click('input[name="rt-view"][value="side"]');

    // Export: the GLB validates, the joints JSON has the skin's joints, the GLB plays here.
    const glb = await download(page, '#rt-export');
    const bytes = fs.readFileSync(glb);
    const report = await (await import('gltf-validator')).validateBytes(new Uint8Array(bytes));
    check(report.issues.numErrors === 0, `gltf-validator: ${report.issues.numErrors} errors: ${JSON.stringify(report.issues.messages.slice(0, 5))}`);
    const jointsPath = await download(page, '#rt-joints-save');
    const jointsJson = JSON.parse(fs.readFileSync(jointsPath, 'utf8'));
    check(Object.keys(jointsJson).length === s1.joints, `joints JSON: ${Object.keys(jointsJson).length} of ${s1.joints}`);
    await page.setInputFiles('#rt-play-file', glb);
    await page.waitForFunction(() => window.__meshmorph.state.retarget.played, null, { timeout: 30000 });
    const played = await rtState(page);
    check(played.played.morphTargets === s2.run.frames, `played GLB: ${JSON.stringify(played.played)}`);
    check(played.playing, 'the opened GLB does not play');
    await page.waitForTimeout(300);
    await nextFrame(page);
    await shot(page, 'retarget-8-glb-played');
    const after = await rtState(page);
    check(after.time !== played.time, 'the opened GLB\'s time does not move');
    await page.click('#rt-back');
    check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  });

  it('retarget: KayKit clip onto the bundled human woman with her joints file and with automatic joints, matching the CLI; an option change recomputes; errors are readable', async ({ page, browser, pageErrors }) => {
    await openJob(page);
    if ((await rtState(page)).source?.id !== 'knight') {
      await chooseCharacter(page, 'knight');
      await chooseClip(page, 'Walking_A');
    }
    await chooseTarget(page, 'woman');
    const s0 = await rtState(page);
    check(s0.jointsFrom === 'file' && s0.joints === 18, `woman joints: ${s0.jointsFrom} ${s0.joints}`);
    await shot(page, 'retarget-9-woman-joints');
    const done = await waitRun(page);
    check(done.target.vertices > 6000, `woman vertices ${done.target.vertices}`);
    const k = 5;
    await page.evaluate(() => window.__meshmorph.hooks.retargetSeek(0.5));
    await nextFrame(page);
    await shot(page, 'retarget-10-woman-playing');
    const pageFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    const rel = compareFrame(pageFrame, cliFrame(['--source', path.join(repoDir, 'data/anim/KayKit/Knight.glb'), '--clip', 'Walking_A',
      '--target', path.join(repoDir, 'data/anim/human_woman.ply'), '--target-joints', path.join(repoDir, 'data/joints/human_woman_kaykit_joints.json')], k, 'retarget-cli-knight-woman'), 'Knight → woman');
    record(browser, 'retarget Knight → woman frame 5: page vs CLI (max / height)', rel.toExponential(2));
    check(rel < 1e-4, `frame ${k} differs from the CLI's by ${rel} of the height`);
    // The same clip with automatic joints: the Knight's curve skeleton has its five limbs (since
    // the thirty-second session; before, 24 limb ends for its blocky parts made the fit fall back
    // to the Knight's own bones), so the fit keeps it; the frame equals the CLI's with
    // --target-joints auto.
    await page.selectOption('#rt-joints-from', 'auto');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.fit.status !== 'fitting' && window.__meshmorph.state.retarget.jointsFrom === 'auto' && window.__meshmorph.state.retarget.joints > 0, null, { timeout: 120000 });
    const kayFit = await rtState(page);
    check(kayFit.fit.status === 'done' && kayFit.joints >= 15 && !kayFit.fit.warnings.some((w) => /own bones/.test(w)), `Knight in the woman, automatic: ${JSON.stringify(kayFit.fit)}, ${kayFit.joints} joints`);
    check(!/own bones/.test(await page.textContent('#rt-target-info')), 'a fallback to the source\'s bones is shown');
    record(browser, 'retarget Knight → woman: automatic joints fitted (ms)', kayFit.fit.ms);
    await waitRun(page);
    await page.evaluate(() => window.__meshmorph.hooks.retargetSeek(0.5));
    await nextFrame(page);
    await shot(page, 'retarget-10b-woman-automatic-joints');
    const autoFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    const relAuto = compareFrame(autoFrame, cliFrame(['--source', path.join(repoDir, 'data/anim/KayKit/Knight.glb'), '--clip', 'Walking_A',
      '--target', path.join(repoDir, 'data/anim/human_woman.ply'), '--target-joints', 'auto'], k, 'retarget-cli-knight-woman-auto'), 'Knight → woman, automatic joints');
    record(browser, 'retarget Knight → woman (automatic joints) frame 5: page vs CLI (max / height)', relAuto.toExponential(2));
    check(relAuto < 1e-4, `automatic joints: frame ${k} differs from the CLI's by ${relAuto} of the height`);
    await page.selectOption('#rt-joints-from', 'file');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.jointsFrom === 'file' && window.__meshmorph.state.retarget.joints === 18, null, { timeout: 30000 });
    await waitRun(page);
    const plot = await page.evaluate(() => window.__meshmorph.hooks.retargetPlot());
    check(plot && plot.every(Number.isFinite), 'no bone-length plot');
    // The core's per-frame checks: self-intersecting triangle pairs (beyond the rest pose's).
    const crossings = await page.evaluate(() => window.__meshmorph.hooks.retargetIntersections());
    check(crossings && crossings.length === plot.length && crossings.every((c) => Number.isInteger(c) && c >= 0), `self-intersections per frame: ${crossings?.slice(0, 5)}`);
    record(browser, 'retarget Knight → woman: self-intersecting pairs, max over frames', Math.max(...crossings));

    // An option change while frames are computing: the run going is cancelled, a new one runs
    // with the option (fps 15 → about half the frames).
    const runs = done.runs;
    await page.click('section.retarget .lil-gui.options > .lil-title');
    await page.fill('#opt-fps', '15');
    await page.click('section.retarget h2'); // the field loses focus: lil-gui's finish-change
    await page.waitForFunction((n) => window.__meshmorph.state.retarget.runs > n, runs, { timeout: 10000 }).catch(async (e) => {
      const st = await rtState(page);
      throw new Error(`${e.message}: runs ${st.runs} (was ${runs}), run ${st.run.status}, fps field "${await page.inputValue('#opt-fps')}", options ${JSON.stringify(st.run.options).slice(0, 300)}`);
    });
    const fewer = await waitRun(page);
    check(Math.abs(fewer.run.frames - Math.ceil(done.run.frames / 2)) <= 1, `fps 15: ${fewer.run.frames} frames vs ${done.run.frames} at 30`);
    // Back to 30: wait for the new run to start first (else waitRun could see the 15 fps run's
    // "done" and then find the new run preparing: "the run failed: undefined", the thirty-second
    // session's fresh clone).
    const runs15 = (await rtState(page)).runs;
    await page.fill('#opt-fps', '30');
    await page.click('section.retarget h2'); // the field loses focus: lil-gui's finish-change
    await page.waitForFunction((n) => window.__meshmorph.state.retarget.runs > n, runs15, { timeout: 10000 });
    await waitRun(page);

    // A source whose skeleton the woman's joints were not placed for: the page says so.
    await chooseCharacter(page, 'robot');
    await chooseClip(page, 'Wave');
    const robot = await rtState(page);
    const info = await page.textContent('#rt-target-info');
    check(robot.joints === 0 && /not for RobotExpressive/.test(info), `robot on woman: ${robot.joints} joints, "${info}"`);
    await shot(page, 'retarget-11-no-joints-for-robot');
    // A joints file of wrong names: the core's message is shown, the page recovers.
    const bad = path.join(shotDir, 'retarget-bad-joints.json');
    fs.writeFileSync(bad, JSON.stringify({ nosuchjoint: [0, 1, 0], another: [0, 0.5, 0] }));
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.setInputFiles('#rt-joints-file', bad);
    await page.waitForFunction(() => window.__meshmorph.state.retarget.run.status === 'error', null, { timeout: 60000 });
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(error && /nosuchjoint|another/.test(error.message), `error: ${JSON.stringify(error)}`);
    await shot(page, 'retarget-12-error');
    // Back to a clip the woman has joints for.
    await chooseCharacter(page, 'knight');
    await chooseTarget(page, 'woman');
    await chooseClip(page, 'Idle');
    await waitRun(page);
    check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  });
  it('retarget: the person\'s own files — a skinned GLB as the source, a PLY target with its joints file', async ({ page, browser, pageErrors }) => {
    await openJob(page);
    await page.setInputFiles('#rt-source-file', path.join(repoDir, 'data/anim/CesiumMan/CesiumMan.glb'));
    await page.waitForFunction(() => window.__meshmorph.state.retarget.source?.id === 'file', null, { timeout: 60000 });
    // Its one clip is chosen without a click (nothing to pick), and listed as selected.
    const one = await page.evaluate(() => ({ clip: window.__meshmorph.state.retarget.source.clip, selected: document.querySelector('#rt-clip').value }));
    check(one.clip === 0 && one.selected === '0', `CesiumMan's only clip was not chosen: ${JSON.stringify(one)}`);
    await page.setInputFiles('#rt-target-file', path.join(repoDir, 'data/anim/human_woman.ply'));
    await page.waitForFunction(() => window.__meshmorph.state.retarget.target?.id === 'file', null, { timeout: 60000 });
    await waitIdle(page);
    const s0 = await rtState(page);
    check(s0.jointsFrom === 'auto', `own PLY target: joints from ${s0.jointsFrom} (automatic expected)`);
    // The person has a joints file: "from a joints file" instead of the automatic fit (cancelled).
    await page.selectOption('#rt-joints-from', 'file');
    await page.setInputFiles('#rt-joints-file', path.join(repoDir, 'data/joints/human_woman_joints.json'));
    await page.waitForFunction(() => window.__meshmorph.state.retarget.joints === 19, null, { timeout: 30000 });
    // CesiumMan's one clip has no name: it is listed as "(unnamed clip 1)".
    const label = await page.textContent('#rt-clip option');
    check(/unnamed clip 1/.test(label), `clip label ${label}`);
    await page.selectOption('#rt-clip', '0');
    const done = await waitRun(page);
    check(done.run.frames > 10 && done.source.clipName === '', `CesiumMan run: ${JSON.stringify(done.run)}`);
    await page.evaluate(() => window.__meshmorph.hooks.retargetSeek(1.0));
    await nextFrame(page);
    await shot(page, 'retarget-13-own-files');
    const firstRun = await page.evaluate(() => window.__meshmorph.hooks.retargetFrame(10));
    const joints = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    check(joints.names.length === 19 && joints.names.includes('Skeleton_torso_joint_1'), `the file's joints were replaced: ${joints.names.slice(0, 3)}`);
    // A cancel the op cannot honour in time (an SVD is one indivisible call; the CI's official
    // run once lost a run that way): with no grace at all, Run pressed while preparing cancels the
    // preparation, the worker is replaced, and the new run — made after the cancel — waits for
    // the new worker instead of dying with the old one.
    // The client logic is the same in every browser: Chromium only (in Firefox this step took
    // ~30 s of a run prepared again).
    if (browser === 'firefox') {
      check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
      return;
    }
    // (An error an earlier case provoked on purpose may still be recorded: cleared first.)
    const restarts = await page.evaluate(() => { window.__meshmorph.state.error = null; return window.__meshmorph.restarts; });
    await page.click('#rt-run');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.run.status === 'preparing', null, { timeout: 10000 });
    const grace = await page.evaluate(() => { const was = window.__meshmorph.client.cancelGraceMs; window.__meshmorph.client.cancelGraceMs = 0; return was; });
    await page.click('#rt-run');
    const again = await waitRun(page).finally(() => page.evaluate((ms) => { window.__meshmorph.client.cancelGraceMs = ms; }, grace));
    const after = await page.evaluate(() => ({ restarts: window.__meshmorph.restarts, status: document.getElementById('status').textContent, error: window.__meshmorph.state.error }));
    check(after.restarts === restarts + 1, `worker restarts ${restarts} → ${after.restarts} (one expected: the cancel had no grace)`);
    check(again.run.frames === done.run.frames && !after.error, `the run after the restart: ${JSON.stringify(again.run)}, error ${JSON.stringify(after.error)}`);
    const rerun = await page.evaluate(() => window.__meshmorph.hooks.retargetFrame(10));
    check(rerun && rerun.length === firstRun.length && rerun.every((v, i) => v === firstRun[i]), 'the run in the new worker gives other positions');
    check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  });
  it('retarget: automatic joints — the Fox skeleton fitted inside the wolf, a joint dragged to pin it, refitted; both runs equal the CLI\'s (--target-joints auto, --markers)', async ({ page, browser, pageErrors }) => {
    await openJob(page);
    await chooseCharacter(page, 'fox');
    await chooseTarget(page, 'wolf'); // its placed joints (for the Fox skeleton) first
    await chooseClip(page, 'Walk');
    await waitRun(page);
    await page.selectOption('#rt-joints-from', 'auto');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.fit.status !== 'fitting' && window.__meshmorph.state.retarget.joints > 0, null, { timeout: 120000 });
    const fitted = await rtState(page);
    check(fitted.fit.status === 'done' && fitted.joints >= 15, `fit: ${JSON.stringify(fitted.fit)}, ${fitted.joints} joints`);
    record(browser, 'retarget Fox → wolf: automatic joints fitted (ms)', fitted.fit.ms);
    const auto = await waitRun(page);
    await nextFrame(page);
    await shot(page, 'retarget-14-automatic-joints');
    const k = 5;
    const wolfArgs = ['--source', path.join(repoDir, 'data/anim/Fox/glTF-Binary/Fox.glb'), '--clip', 'Walk', '--target', path.join(repoDir, 'data/anim/wolf0.ply'), '--target-joints', 'auto'];
    const autoFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    const relAuto = compareFrame(autoFrame, cliFrame(wolfArgs, k, 'retarget-cli-fox-wolf-auto'), 'Fox → wolf, automatic joints');
    record(browser, 'retarget Fox → wolf (automatic joints) frame 5: page vs CLI (max / height)', relAuto.toExponential(2));
    // The fits agree to 1e-13. The thirty-second session measured 2.49e-4 here: the retargeting's
    // surface descriptors picked their bone by the last bits at shared joints (a 1e-9 joint move
    // moved frames by 4.6e-3 of the height). Fixed in the thirty-third: 2.37e-8.
    check(relAuto < 1e-4, `automatic joints: frame ${k} differs from the CLI's by ${relAuto} of the height`);

    // Edit joints: playback pauses, the target shows its rest pose. Drag a joint with the real
    // mouse (press on its sphere, move, release): it is pinned there and the others are fitted
    // again around it; a new run starts.
    await page.click('#rt-edit-joints');
    const editing = await rtState(page);
    check(editing.editingJoints && !editing.playing, `edit joints: ${JSON.stringify({ editing: editing.editingJoints, playing: editing.playing })}`);
    const before = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const j = before.names.findIndex((n) => /head/i.test(n)) >= 0 ? before.names.findIndex((n) => /head/i.test(n)) : before.names.length - 1;
    const at = await page.evaluate((i) => window.__meshmorph.hooks.retargetJointOnScreen(i), j);
    const runs = auto.runs;
    const under = await page.evaluate(([x, y]) => window.__meshmorph.hooks.retargetJointAt(x, y), [at.x, at.y]);
    check(under === j, `joint under the pointer: ${under}, expected ${j} at ${JSON.stringify(at)}`);
    const camera = await page.evaluate(() => window.__meshmorph.hooks.retargetCamera());
    await page.mouse.move(at.x, at.y);
    await page.mouse.down();
    for (let step = 1; step <= 5; ++step) await page.mouse.move(at.x, at.y + step, { steps: 1 });
    await page.mouse.up();
    await page.waitForFunction((n) => Object.keys(window.__meshmorph.state.retarget.pins).length === 1 && window.__meshmorph.state.retarget.fit.status === 'done' && window.__meshmorph.state.retarget.runs > n, runs, { timeout: 120000 })
      .catch(async (e) => {
        const st = await rtState(page);
        const err = await page.evaluate(() => window.__meshmorph.state.error);
        throw new Error(`${e.message}: pins ${JSON.stringify(st.pins)}, fit ${JSON.stringify(st.fit)}, runs ${st.runs} (was ${runs}), error ${JSON.stringify(err)}, info "${await page.textContent('#rt-target-info')}"`);
      });
    const pinned = await waitRun(page);
    const pin = pinned.pins[before.names[j]];
    check(pin, `no pin for ${before.names[j]}: ${JSON.stringify(pinned.pins)}`);
    const after = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const moved = Math.hypot(...before.positions[j].map((v, c) => v - pin[c]));
    const heightOfTarget = heightOf(after.positions.flat());
    check(moved > 0, 'the drag did not move the joint');
    const kept = Math.hypot(...after.positions[j].map((v, c) => v - pin[c]));
    check(kept < 0.02 * heightOfTarget, `the pinned joint is ${kept} away from where it was dropped (height ${heightOfTarget})`);
    const cameraAfter = await page.evaluate(() => window.__meshmorph.hooks.retargetCamera());
    check(cameraAfter.every((v, c) => v === camera[c]), 'the joint drag orbited the camera');
    await nextFrame(page);
    await shot(page, 'retarget-15-pinned-joint');
    // The pins as the CLI's markers file: the same frame from `--markers`.
    const pinsFile = await download(page, '#rt-pins-save');
    const pinsJson = JSON.parse(fs.readFileSync(pinsFile, 'utf8'));
    check(Object.keys(pinsJson).length === 1, `pins file: ${JSON.stringify(pinsJson)}`);
    const pinnedFrame = await page.evaluate((i) => window.__meshmorph.hooks.retargetFrame(i), k);
    const relPinned = compareFrame(pinnedFrame, cliFrame([...wolfArgs, '--markers', pinsFile], k, 'retarget-cli-fox-wolf-pinned'), 'pinned');
    record(browser, 'retarget Fox → wolf (one pinned joint) frame 5: page vs CLI (max / height)', relPinned.toExponential(2));
    // As above (1.36e-3 before the fix, 2.37e-8 after).
    check(relPinned < 1e-4, `pinned joints: frame ${k} differs from the CLI's by ${relPinned} of the height`);
    // A joint dragged far outside the wolf stops at its surface (the page keeps dragged joints
    // inside): the core takes the pin where it stopped, far from where the pointer went.
    const held = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const k2 = held.names.findIndex((n) => !(n in pinsJson));
    const at2 = await page.evaluate((i) => window.__meshmorph.hooks.retargetJointOnScreen(i), k2);
    const fits = (await rtState(page)).fit.fits;
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.mouse.move(at2.x, at2.y);
    await page.mouse.down();
    for (let step = 1; step <= 6; ++step) await page.mouse.move(at2.x + 40 * step, at2.y - 25 * step, { steps: 1 });
    const farX = at2.x + 240;
    const farY = at2.y - 150;
    await page.mouse.up();
    await page.waitForFunction((n) => Object.keys(window.__meshmorph.state.retarget.pins).length === 2 && window.__meshmorph.state.retarget.fit.status === 'done' && window.__meshmorph.state.retarget.fit.fits > n, fits, { timeout: 120000 })
      .catch(async (e) => {
        const st = await rtState(page);
        const err = await page.evaluate(() => window.__meshmorph.state.error);
        throw new Error(`${e.message}: pins ${JSON.stringify(st.pins)}, fit ${JSON.stringify(st.fit)}, error ${JSON.stringify(err)}, info "${await page.textContent('#rt-target-info')}"`);
      });
    await waitRun(page);
    const stopped = await page.evaluate(() => window.__meshmorph.state.error);
    check(stopped == null, `a joint dragged outside gave an error: ${JSON.stringify(stopped)}`);
    const landed = await page.evaluate((i) => window.__meshmorph.hooks.retargetJointOnScreen(i), k2);
    check(Math.hypot(landed.x - farX, landed.y - farY) > 60, `the joint followed the pointer out of the mesh: at ${JSON.stringify(landed)}, pointer released at ${farX}, ${farY}`);
    check(Math.hypot(landed.x - at2.x, landed.y - at2.y) > 1, `the joint did not move toward the pointer: ${JSON.stringify(landed)} vs ${JSON.stringify(at2)}`);
    const drawnPins = await page.evaluate(() => window.__meshmorph.hooks.retargetPinnedDrawn());
    const pinNames = Object.keys((await rtState(page)).pins);
    check(drawnPins.length === 2 && drawnPins.every((i) => pinNames.includes(held.names[i])), `pins drawn red after the refit: ${JSON.stringify(drawnPins)} for ${JSON.stringify(pinNames)}`);
    await shot(page, 'retarget-16-joint-stopped-at-surface');
    // A pin the core refuses (here dropped far outside, past the drag's inside constraint, as a
    // surface the page's inside test misjudges would): taken back with the core's message, the
    // two pins and the joints as they were.
    const beforeDrop = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const fitsBefore = (await rtState(page)).fit.fits;
    const outside = beforeDrop.positions[0].map((x, c) => x + (c === 0 ? 10 : 0) * Math.max(...beforeDrop.positions.map((p) => Math.abs(p[0]))) + (c === 0 ? 1 : 0));
    await page.evaluate(([j, p]) => window.__meshmorph.hooks.retargetDropJoint(j, p), [0, outside]);
    await page.waitForFunction(() => /was not pinned/.test(document.querySelector('#rt-target-info').textContent) && window.__meshmorph.state.retarget.fit.status === 'done', null, { timeout: 120000 });
    const refused = await rtState(page);
    const afterDrop = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    check(Object.keys(refused.pins).length === 2 && !(beforeDrop.names[0] in refused.pins && !pinNames.includes(beforeDrop.names[0])), `pins after the refused drop: ${JSON.stringify(Object.keys(refused.pins))}`);
    check(JSON.stringify(afterDrop.positions) === JSON.stringify(beforeDrop.positions), 'the joints moved after a refused pin');
    check(refused.fit.fits === fitsBefore, `a refused pin counted as a fit: ${refused.fit.fits} vs ${fitsBefore}`);
    const refusal = await page.textContent('#rt-target-info');
    check(/outside the target surface/.test(refusal), `the core's reason is not shown: "${refusal}"`);
    check(await page.evaluate(() => window.__meshmorph.state.error) == null, 'a refused pin raised the error banner as well');
    await shot(page, 'retarget-16b-pin-refused');
    // Clear pins: fitted again without them.
    await page.click('#rt-pins-clear');
    await page.waitForFunction(() => Object.keys(window.__meshmorph.state.retarget.pins).length === 0 && window.__meshmorph.state.retarget.fit.status === 'done' && window.__meshmorph.state.retarget.joints > 0, null, { timeout: 120000 });
    await waitRun(page);
    // The context graph (option context_graph on): a new run, then its graph over the target.
    await page.click('#rt-edit-joints'); // editing off: the frames play again
    await page.click('section.retarget .lil-gui.options > .lil-title');
    await page.selectOption('#opt-context_graph', 'on');
    await page.waitForFunction(() => window.__meshmorph.state.retarget.graph.sets > 0, null, { timeout: 240000 });
    await page.check('#rt-graph');
    const withGraph = await rtState(page);
    check(withGraph.run.options.context_graph === 'on' && withGraph.graph.nodes > 50 && withGraph.graph.edges > 50, `context graph: ${JSON.stringify(withGraph.graph)}`);
    record(browser, 'retarget Fox → wolf: context graph over the target (sets / nodes / edges)', `${withGraph.graph.sets} / ${withGraph.graph.nodes} / ${withGraph.graph.edges}`);
    // Its source side: nodes by body part and edges over the Fox, on its skinned surface at the
    // bind pose (the core's source units), following the clip.
    check(withGraph.graph.sourceSets >= 3 && withGraph.graph.sourceNodes > 50 && withGraph.graph.sourceEdges > 50, `source graph: ${JSON.stringify(withGraph.graph)}`);
    const nodesAt = async (t) => {
      await page.evaluate((time) => window.__meshmorph.hooks.retargetSeek(time), t);
      return page.evaluate(() => window.__meshmorph.hooks.retargetSourceGraph());
    };
    const n0 = await nodesAt(0.1);
    const n1 = await nodesAt(0.5);
    const extent = (a) => Math.hypot(...[0, 1, 2].map((c) => Math.max(...a.filter((_, i) => i % 3 === c)) - Math.min(...a.filter((_, i) => i % 3 === c))));
    const nodesMoved = Math.max(...n0.map((x, i) => Math.abs(x - n1[i])));
    check(withGraph.graph.sourceGap < 1e-3 * extent(n0), `source graph nodes off the Fox's bind-pose surface: ${withGraph.graph.sourceGap} (extent ${extent(n0)})`);
    check(nodesMoved > 0.01 * extent(n0), `the source graph does not follow the clip: moved ${nodesMoved} (extent ${extent(n0)})`);
    record(browser, 'retarget Fox → wolf: source graph (parts / nodes / edges; farthest node from the bind-pose surface / extent)',
      `${withGraph.graph.sourceSets - 1} / ${withGraph.graph.sourceNodes} / ${withGraph.graph.sourceEdges}; ${(withGraph.graph.sourceGap / extent(n0)).toExponential(2)}`);
    await nextFrame(page);
    await shot(page, 'retarget-17-context-graph');
    check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  });
  it('retarget: a refused automatic fit (the Fox\'s skeleton in a horse without a tail) goes on with pins clicked and pins loaded from a markers file; the joints equal the CLI\'s (joints --markers)', async ({ page, browser, pageErrors }) => {
    // TOSCA's horse0 (z up, head at −y) has no tail: the Fox's tail finds no partner, and the fit
    // asks for pins. The pins: points on the horse's mid-plane in its head and at its rump, from
    // its bounding box (the places a person would click).
    const horse = path.join(repoDir, 'data/pose/horse0.ply');
    const fox = path.join(repoDir, 'data/anim/Fox/glTF-Binary/Fox.glb');
    const box = /bounding box: \[\s*(\S+)\s+(\S+)\s+(\S+)\s*\] - \[\s*(\S+)\s+(\S+)\s+(\S+)\s*\]/.exec(cli(['info', horse], 'info horse0')).slice(1).map(Number);
    const [x0, y0, , x1, y1, z1] = box;
    const hHorse = z1 - box[2];
    const midX = 0.5 * (x0 + x1), len = y1 - y0;
    const headAt = [midX, y0 + 0.08 * len, 0.8 * z1], rumpAt = [midX, y1 - 0.06 * len, 0.62 * z1];
    await openJob(page);
    await chooseCharacter(page, 'fox');
    await page.setInputFiles('#rt-target-file', horse);
    await page.waitForFunction(() => window.__meshmorph.state.retarget.target?.id === 'file', null, { timeout: 60000 });
    await page.waitForFunction(() => window.__meshmorph.state.retarget.fit.status === 'error', null, { timeout: 120000 });
    // The core's refusal names the limb (the Fox's tail) and asks for markers; with no joints to
    // drag, the page offers pins by clicking and from a file.
    const refusal = await page.textContent('#rt-target-info');
    check(/pin those joints with markers/.test(refusal) && /b_Tail03_014/.test(refusal) && !/b_Head_05/.test(refusal) && /Load pins/.test(refusal), `the refusal: "${refusal}"`);
    check(await page.isVisible('#rt-pins-load'), 'no Load pins… after the refused fit');
    check(await page.isDisabled('#rt-edit-joints'), 'Edit joints is offered with no joints to edit');
    await page.evaluate(() => document.querySelector('#rt-pins-row').scrollIntoView({ block: 'center' }));
    await shot(page, 'retarget-17-fit-refused');
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    // First by clicking: the refusal's joints come first in "Click to pin". A pin on the head (more
    // than 3 bones from the tail) leaves the fit refused and stays; one on the tail's root at the
    // rump makes it. Each pin lands in the middle of the body under a real click; the joints equal
    // the CLI's with the page's two pins as the markers.
    const choices = await page.evaluate(() => [...document.querySelectorAll('#rt-pin-joint option')].map((o) => o.textContent));
    check(choices.length > 15 && /named in the message/.test(choices[1]), `Click to pin's joints: ${JSON.stringify(choices.slice(0, 4))} (${choices.length})`);
    const clickPin = async (joint, at, expect) => {
      await page.selectOption('#rt-pin-joint', joint);
      const hint = await page.textContent('#rt-pins-info');
      check(new RegExp(`Click on .* where ${joint} is`).test(hint), `the hint while placing: "${hint}"`);
      const screen = await page.evaluate((p) => window.__meshmorph.hooks.retargetPointOnScreen(p), at);
      // A refit that is refused again sets the error banner again (the test cleared it, and so
      // does the pin); a fit that goes on counts one more fit.
      await page.evaluate(() => { window.__meshmorph.state.error = null; });
      const fitsBefore = (await rtState(page)).fit.fits;
      await page.mouse.click(screen.x, screen.y);
      await page.waitForFunction(([n, refused]) => {
        const { retarget, error } = window.__meshmorph.state;
        return retarget.fit.status !== 'fitting' && (refused ? retarget.fit.status === 'error' && error != null : retarget.fit.fits > n);
      }, [fitsBefore, expect === 'error'], { timeout: 120000 })
        .catch(async (e) => {
          const st = await rtState(page);
          throw new Error(`${e.message}: pins ${JSON.stringify(st.pins)}, fit ${JSON.stringify(st.fit)}, info "${await page.textContent('#rt-pins-info')}"`);
        });
      const st = await rtState(page);
      check(st.fit.status === expect && joint in st.pins, `after the click on ${joint}: pins ${JSON.stringify(st.pins)}, fit ${JSON.stringify(st.fit)}`);
      const pin = st.pins[joint];
      const off = Math.hypot(...pin.map((v, c) => v - at[c])) / hHorse;
      record(browser, `retarget Fox → horse0, ${joint} pinned by a click: pin to the point clicked at (/ height)`, off.toFixed(4));
      check(off < 0.15, `the clicked pin ${JSON.stringify(pin)} is far from ${JSON.stringify(at)}`);
      return st;
    };
    await clickPin('b_Head_05', headAt, 'error');
    const clicked = await clickPin('b_Tail01_012', rumpAt, 'done');
    check(clicked.joints > 0 && Object.keys(clicked.pins).sort().join() === 'b_Head_05,b_Tail01_012', `after the clicks: pins ${JSON.stringify(clicked.pins)}`);
    check(await page.evaluate(() => window.__meshmorph.state.error) == null, 'the refusal\'s banner stayed after the clicks made the fit');
    const clickedJoints = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const clickFile = path.join(shotDir, 'fox-in-horse-clicked-pins.json');
    fs.writeFileSync(clickFile, JSON.stringify(clicked.pins));
    const cliClickFile = path.join(shotDir, 'fox-in-horse-clicked-joints.json');
    cli(['joints', horse, '--like', fox, '--markers', clickFile, '--out', cliClickFile], 'joints --markers (the clicked pins)');
    const byCliClick = JSON.parse(fs.readFileSync(cliClickFile, 'utf8'));
    const worstClick = Math.max(...clickedJoints.names.map((n, j) => (n in byCliClick ? Math.hypot(...clickedJoints.positions[j].map((v, c) => v - byCliClick[n][c])) : Infinity)));
    record(browser, 'retarget Fox → horse0, 2 pins clicked after the refusal: page vs CLI joints (max / height)', (worstClick / hHorse).toExponential(2));
    check(clickedJoints.names.length === Object.keys(byCliClick).length && worstClick / hHorse < 2e-3, `the page's joints after the clicks differ from the CLI's by ${worstClick / hHorse} of the height`);
    // The Fox's head lands in the front third of the horse (the facing; 0.28, the base of its long
    // neck), its hips at the back (0.84), on the curve skeleton (the Fox's own bones lose a foot).
    const at = (name) => clickedJoints.positions[clickedJoints.names.indexOf(name)];
    check((at('b_Head_05')[1] - y0) / len < 0.35 && (at('b_Hip_01')[1] - y0) / len > 0.5, `head at ${(at('b_Head_05')[1] - y0) / len}, hips at ${(at('b_Hip_01')[1] - y0) / len} of the length from the front`);
    await nextFrame(page);
    await page.evaluate(() => document.querySelector('#rt-pins-row').scrollIntoView({ block: 'center' }));
    await shot(page, 'retarget-17b-pin-clicked');
    // Then two from a file (replacing the clicked ones): the tail's root and the head, at the points.
    const markersFile = path.join(shotDir, 'fox-in-horse-markers.json');
    fs.writeFileSync(markersFile, JSON.stringify({ b_Tail01_012: rumpAt, b_Head_05: headAt }));
    // A new fit (the clicked pin's fit is done already: the file's change event is handled after
    // setInputFiles returns).
    const fitsBeforeFile = (await rtState(page)).fit.fits;
    await page.setInputFiles('#rt-pins-file', markersFile);
    await page.waitForFunction((n) => window.__meshmorph.state.retarget.fit.fits > n && window.__meshmorph.state.retarget.fit.status === 'done' && window.__meshmorph.state.retarget.joints > 0, fitsBeforeFile, { timeout: 120000 })
      .catch(async (e) => {
        const st = await rtState(page);
        throw new Error(`${e.message}: pins ${JSON.stringify(st.pins)}, fit ${JSON.stringify(st.fit)}, info "${await page.textContent('#rt-target-info')}"`);
      });
    const st = await rtState(page);
    check(Object.keys(st.pins).length === 2, `pins after loading: ${JSON.stringify(Object.keys(st.pins))}`);
    const info = await page.textContent('#rt-target-info');
    check(/placed from your markers/.test(info) && !/own bones instead/.test(info), `the fit's warnings: "${info}"`);
    check(!(await page.isVisible('#error')), 'the refusal\'s banner is still shown after the pins made the fit');
    const joints = await page.evaluate(() => window.__meshmorph.hooks.retargetJoints());
    const cliFile = path.join(shotDir, 'fox-in-horse-joints.json');
    cli(['joints', horse, '--like', fox, '--markers', markersFile, '--out', cliFile], 'joints --markers');
    const byCli = JSON.parse(fs.readFileSync(cliFile, 'utf8'));
    check(joints.names.length === Object.keys(byCli).length && joints.names.every((n) => n in byCli), `page joints ${joints.names.length}, CLI ${Object.keys(byCli).length}`);
    const worst = Math.max(...joints.names.map((n, j) => Math.hypot(...joints.positions[j].map((v, c) => v - byCli[n][c]))));
    record(browser, 'retarget Fox → horse0, 2 pins loaded after the refusal: page vs CLI joints (max / height)', (worst / hHorse).toExponential(2));
    check(worst / hHorse < 2e-3, `the page's joints differ from the CLI's by ${worst / hHorse} of the height`);  // as above
    for (const [name, p] of Object.entries(st.pins)) {
      const j = joints.names.indexOf(name);
      check(j >= 0 && Math.hypot(...joints.positions[j].map((v, c) => v - p[c])) < 1e-6 * hHorse, `${name} is not held at its pin`);
    }
    await nextFrame(page);
    await shot(page, 'retarget-18-pins-loaded');
    check(pageErrors.length === 0, `uncaught page errors: ${pageErrors.join(' | ')}`);
  });
}
