// End-to-end tests of the Merge job (web/src/ui/panels/merge.js), registered by tests/e2e/run.mjs
// (`registerMergeTests(it, helpers)`): the real mouse picks the key vertices of the bundled pair
// (the horse cut at the neck + the camel's head), the merge runs in the worker, and the merged
// mesh is compared with `meshmorph merge` on the spec the page saved (MM_CLI); the GLB is
// downloaded, validated and opened again; the cut tools open a closed mesh; the dependent mode
// places the source, brushes a fixed handle and merges; errors are shown.
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';

// The vertices of an OFF file (the CLI writes them with 17 significant digits).
export function readOffVertices(text) {
  const tokens = text.replace(/#[^\n]*/g, ' ').split(/\s+/).filter(Boolean);
  if (tokens[0] !== 'OFF') throw new Error('not an OFF file');
  const count = Number(tokens[1]);
  const faces = Number(tokens[2]);
  const positions = new Float64Array(count * 3);
  for (let i = 0; i < count * 3; ++i) positions[i] = Number(tokens[4 + i]);
  const indices = [];
  let at = 4 + count * 3;
  for (let f = 0; f < faces; ++f) {
    const n = Number(tokens[at]);
    for (let k = 1; k <= n; ++k) indices.push(Number(tokens[at + k]));
    at += n + 1;
  }
  return { positions, indices };
}

const diagonalOf = (p) => {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < p.length; i += 3) for (let k = 0; k < 3; ++k) { lo[k] = Math.min(lo[k], p[i + k]); hi[k] = Math.max(hi[k], p[i + k]); }
  return Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
};

export function registerMergeTests(it, { check, shot, nextFrame, waitIdle, canvasPixels, pixelStats, repoDir, shotDir, cliPath }) {
  const mergeState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.__meshmorph.state.merge)));
  const exampleSpec = JSON.parse(fs.readFileSync(path.join(repoDir, 'data/specs/merge-camelhead-horse.json'), 'utf8'));
  const neckCut = ['--plane', '0', '-85', '140', '0', '-1', '1', '--keep', '0', '0', '100'];

  function cli(args, label) {
    check(fs.existsSync(cliPath), `the CLI is missing: ${cliPath} (set MM_CLI)`);
    const started = Date.now();
    const run = spawnSync(cliPath, args, { encoding: 'utf8', timeout: 300000 });
    check(run.status === 0, `meshmorph ${label} failed (${run.status}): ${run.stderr}${run.stdout}`);
    return { stdout: run.stdout, ms: Date.now() - started };
  }

  // Clicks a boundary vertex with the real mouse; when the camera does not see it, "Look" turns
  // the camera to that mesh's loop first (what a person would do). Returns the state after.
  async function clickKey(page, side, vertex) {
    let at = await page.evaluate(([s, v]) => window.__meshmorph.hooks.mergeVertexOnScreen(s, v), [side, vertex]);
    if (!at.visible) {
      await page.click(`#mg-${side}-look`);
      await nextFrame(page);
      at = await page.evaluate(([s, v]) => window.__meshmorph.hooks.mergeVertexOnScreen(s, v), [side, vertex]);
    }
    check(at.visible, `${side} key ${vertex} is not visible even after Look (${JSON.stringify(at)})`);
    await page.mouse.move(at.x, at.y, { steps: 4 });
    await page.mouse.down();
    await page.mouse.up();
    await nextFrame(page);
    return mergeState(page);
  }

  async function openExample(page) {
    await page.click('#jobs button[data-job="merge"]');
    await page.waitForSelector('#mg-example', { state: 'visible' });
    await waitIdle(page);
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.click('#mg-example');
    await page.waitForFunction(() => (window.__meshmorph.state.merge.target?.cuts.length === 1 && window.__meshmorph.state.merge.source?.name === 'camelhead.ply') || window.__meshmorph.state.error, null, { timeout: 60000 });
    await waitIdle(page);
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(!error, `the example did not load: ${JSON.stringify(error)}`);
    await nextFrame(page);
  }

  async function pickExampleKeys(page) {
    const { target_keys: tk, source_keys: sk } = exampleSpec.pairs[0];
    for (let i = 0; i < tk.length; ++i) {
      let m = await clickKey(page, 'target', tk[i]);
      check(m.pending?.side === 'target' && m.pending.vertex === tk[i], `target click ${i + 1}: expected vertex ${tk[i]}, state ${JSON.stringify(m.pending)}`);
      m = await clickKey(page, 'source', sk[i]);
      check(m.pairs.length === i + 1 && m.pairs[i][0] === tk[i] && m.pairs[i][1] === sk[i], `pair ${i + 1}: expected [${tk[i]}, ${sk[i]}], got ${JSON.stringify(m.pairs)}`);
    }
  }

  async function download(page, selector) {
    const [file] = await Promise.all([page.waitForEvent('download', { timeout: 30000 }), page.click(selector)]);
    const out = path.join(shotDir, file.suggestedFilename());
    await file.saveAs(out);
    return out;
  }

  async function runMerge(page, runs) {
    await page.click('#mg-run');
    await page.waitForFunction((n) => window.__meshmorph.state.merge.runs >= n || window.__meshmorph.state.error, runs, { timeout: 120000 });
    await waitIdle(page);
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(!error, `merge failed: ${JSON.stringify(error)}`);
    await nextFrame(page);
  }

  // Page result against `meshmorph merge` on the given inputs: same faces, vertices within
  // 1e-9 of the diagonal. Returns the CLI's time.
  function compareWithCli(pageResult, { target, source, spec, label }) {
    const out = path.join(shotDir, `merge-${label}-cli.off`);
    const run = cli(['merge', '--target', target, '--source', source, '--spec', spec, '--out', out], `merge (${label})`);
    const ref = readOffVertices(fs.readFileSync(out, 'utf8'));
    check(ref.positions.length === pageResult.positions.length, `${label}: the CLI merged ${ref.positions.length / 3} vertices, the page ${pageResult.positions.length / 3}`);
    check(ref.indices.length === pageResult.indices.length && ref.indices.every((v, i) => v === pageResult.indices[i]), `${label}: the CLI's faces differ from the page's`);
    const diagonal = diagonalOf(ref.positions);
    let error = 0;
    const p = pageResult.positions;
    for (let i = 0; i < p.length; i += 3) error = Math.max(error, Math.hypot(ref.positions[i] - p[i], ref.positions[i + 1] - p[i + 1], ref.positions[i + 2] - p[i + 2]));
    console.log(`     page vs CLI (${label}): max vertex difference ${(error / diagonal).toExponential(2)}·diag; CLI ${run.ms} ms (${run.stdout.split('\n').find((l) => /precompute/.test(l))?.trim()})`);
    check(error <= 1e-9 * diagonal, `${label}: page and CLI differ by ${error / diagonal}·diag`);
    return run.ms;
  }

  it('merge: the bundled pair, keys clicked on both boundaries, merged like the CLI on the saved spec, GLB downloaded and opened again', async ({ page, pageErrors }) => {
    const errorsBefore = pageErrors.length;
    await openExample(page);
    let m = await mergeState(page);
    check(m.target.weldedVertices === 13102 && m.target.loops.length === 1 && m.source.loops.length === 1 && m.source.loops[0] === 56,
      `meshes: ${JSON.stringify({ target: m.target, source: m.source })}`);
    check(m.loops.target === 0 && m.loops.source === 0 && m.step === 3, `loops ${JSON.stringify(m.loops)}, step ${m.step}`);
    const stats = pixelStats(await canvasPixels(page));
    check(stats.foreground > 0.04, `the pair is not drawn (${(stats.foreground * 100).toFixed(1)}% foreground)`);
    check((await page.textContent('#mg-steps .current')).includes('Click a point on the target'), 'the current step does not name the next action');
    await shot(page, 'merge-1-pair');
    // The widths are sliders (× a diagonal) over the range that matters; a typed larger value
    // widens the slider instead of being cut to it.
    const sliders = await page.evaluate(() => ['roi_width', 'transition_target_width', 'transition_source_width']
      .map((n) => Boolean(document.querySelector(`#opt-${n}`)?.closest('.lil-controller')?.querySelector('.lil-slider'))));
    check(sliders.every(Boolean), `width sliders: ${JSON.stringify(sliders)}`);
    await page.click('#mg-options .lil-gui.options > .lil-title');
    await page.fill('#opt-roi_width', '2.5');
    await page.press('#opt-roi_width', 'Enter');
    await page.click('section.merge h2');
    const typed = await page.inputValue('#opt-roi_width');
    check(Number(typed) === 2.5, `roi_width typed 2.5, kept ${typed}`);
    await page.fill('#opt-roi_width', '0.25');
    await page.press('#opt-roi_width', 'Enter');
    await page.click('section.merge h2');
    await page.click('#mg-options .lil-gui.options > .lil-title');

    // Keys by clicking, as data/specs/merge-camelhead-horse.json has them.
    const { target_keys: tk, source_keys: sk } = exampleSpec.pairs[0];
    let at = await page.evaluate(([v]) => window.__meshmorph.hooks.mergeVertexOnScreen('target', v), [tk[0]]);
    if (!at.visible) await page.click('#mg-target-look');
    await nextFrame(page);
    m = await clickKey(page, 'target', tk[0]);
    check(m.pending?.side === 'target' && m.pending.vertex === tk[0], `first target click: ${JSON.stringify(m.pending)}`);
    await shot(page, 'merge-2-first-key');
    m = await clickKey(page, 'source', sk[0]);
    check(m.pairs.length === 1 && m.pairs[0][0] === tk[0] && m.pairs[0][1] === sk[0], `pair 1 ${JSON.stringify(m.pairs)}`);
    m = await clickKey(page, 'target', tk[1]);
    m = await clickKey(page, 'source', sk[1]);
    check(JSON.stringify(m.pairs) === JSON.stringify([[tk[0], sk[0]], [tk[1], sk[1]]]), `pairs ${JSON.stringify(m.pairs)}`);
    check(m.step === 4 && !m.problem, `after two pairs: step ${m.step}, problem ${m.problem}`);
    check(await page.locator('table.merge-keys tbody tr').count() === 2, 'the table does not list 2 pairs');
    await page.click('#mg-frame');
    await nextFrame(page);
    await shot(page, 'merge-3-keys');
    await page.click('#mg-source-look');
    await nextFrame(page);
    await shot(page, 'merge-3-keys-look-source');
    await page.click('#mg-frame');

    // The table reorders pairs (↑ / ↓); the out-of-order case is the next test.
    await page.click('table.merge-keys tbody tr[data-index="1"] button[title^="Move pair 2 up"]');
    m = await mergeState(page);
    check(JSON.stringify(m.pairs) === JSON.stringify([[tk[1], sk[1]], [tk[0], sk[0]]]), `reorder: ${JSON.stringify(m.pairs)}`);
    await page.click('table.merge-keys tbody tr[data-index="0"] button[title^="Move pair 1 down"]');

    // Save the spec (the CLI's JSON).
    const specFile = await download(page, '#mg-save');
    const saved = JSON.parse(fs.readFileSync(specFile, 'utf8'));
    check(JSON.stringify(saved.pairs) === JSON.stringify([{ target_keys: tk, source_keys: sk }]), `saved pairs ${JSON.stringify(saved.pairs)}`);
    check(/meshmorph cut horse0\.ply --plane 0 -85 140 0 -1 1 --keep 0 0 100/.test(saved.comment), `the comment does not say how the target was made: ${saved.comment}`);

    // Merge with progress; the result is watertight.
    await page.click('#mg-run');
    await page.waitForFunction(() => window.__meshmorph.state.busy, null, { timeout: 10000 }).catch(() => {});
    await shot(page, 'merge-4-running');
    await page.waitForFunction(() => window.__meshmorph.state.merge.runs >= 1 || window.__meshmorph.state.error, null, { timeout: 120000 });
    await waitIdle(page);
    check(!(await page.evaluate(() => window.__meshmorph.state.error)), `merge failed: ${JSON.stringify(await page.evaluate(() => window.__meshmorph.state.error))}`);
    m = await mergeState(page);
    check(m.result.boundaryLoops === 0 && m.step === 5, `result ${JSON.stringify({ loops: m.result.boundaryLoops, step: m.step })}`);
    const seam = m.result.seams[0];
    check(seam.zipFaces > 0 && seam.flippedFaces === 0, `seam ${JSON.stringify(seam)}`);
    const report = await page.textContent('#mg-report');
    check(/zip faces/.test(report) && /dihedral/.test(report) && /flipped/.test(report) && /watertight/.test(report), `report: ${report}`);
    await nextFrame(page);
    check(pixelStats(await canvasPixels(page)).coloured > 0.0005, 'the seam is not highlighted');
    await shot(page, 'merge-5-result');
    await page.locator('#mg-report').scrollIntoViewIfNeeded();
    await shot(page, 'merge-5-result-report');

    // The same as the CLI on the saved spec (target made with `meshmorph cut`, full precision).
    const horseBody = path.join(shotDir, 'horse0-cut1.off');
    cli(['cut', path.join(repoDir, 'data/pose/horse0.ply'), ...neckCut, '--out', horseBody], 'cut');
    const pageResult = await page.evaluate(() => window.__meshmorph.hooks.mergeResult());
    const cliMs = compareWithCli(pageResult, { target: horseBody, source: path.join(repoDir, 'data/edit/camelhead.ply'), spec: specFile, label: 'independent' });
    console.log(`     merge in the page: ${m.result.milliseconds.toFixed(0)} ms in the worker (${m.result.wallMs.toFixed(0)} ms with the transfer; precompute ${m.result.stats.ms.precompute.toFixed(0)}, solve ${m.result.stats.ms.solve.toFixed(0)}, zip ${m.result.stats.ms.zip.toFixed(0)} ms) · CLI ${cliMs} ms (whole process)`);

    // Fig. 1: the source moved at random merges to the same mesh.
    await page.click('#mg-check');
    await page.waitForFunction(() => window.__meshmorph.state.merge.check || window.__meshmorph.state.error, null, { timeout: 120000 });
    await waitIdle(page);
    const moved = (await mergeState(page)).check;
    console.log(`     moved source: max difference ${moved.maxDifference?.toExponential(2)}·diag`);
    check(moved.same && moved.maxDifference < 1e-5, `a moved source gives another mesh: ${JSON.stringify(moved)}`);

    // Cancel: a second merge stopped from the progress overlay leaves the first result.
    await page.click('#mg-run');
    await page.waitForFunction(() => window.__meshmorph.state.busy?.label && !document.getElementById('progress').hidden, null, { timeout: 10000 });
    // At once: on an idle machine the whole merge takes a few hundred ms (the cancel flag holds
    // the request's id, so a cancel that arrives before the op starts still stops it).
    await page.click('#cancel', { timeout: 10000 });
    await waitIdle(page, 15000);
    const cancelled = await page.evaluate(() => window.__meshmorph.state.error);
    check(cancelled?.code === 'Cancelled', `expected a Cancelled error, got ${JSON.stringify(cancelled)}`);
    check((await mergeState(page)).runs === 1, 'the cancelled merge counted as a run');
    check((await page.evaluate(() => window.__meshmorph.hooks.mergeResult()))?.positions.length === pageResult.positions.length, 'the cancelled merge dropped the result');
    await page.click('#error-close');
    await page.evaluate(() => { window.__meshmorph.state.error = null; });

    // Download the GLB, validate it, open it again (Mesh job).
    const glbFile = await download(page, '#mg-export');
    const bytes = fs.readFileSync(glbFile);
    check(path.basename(glbFile) === 'horse0-merged.glb' && bytes.subarray(0, 4).toString('latin1') === 'glTF', `bad GLB ${glbFile}`);
    const validation = await (await import('gltf-validator')).validateBytes(new Uint8Array(bytes));
    check(validation.issues.numErrors === 0, `merged GLB: glTF-Validator: ${JSON.stringify(validation.issues.messages.slice(0, 3))}`);
    await page.click('#jobs button[data-job="mesh"]');
    const loads = await page.evaluate(() => window.__meshmorph.state.loads);
    await page.setInputFiles('#file', glbFile);
    await page.waitForFunction((n) => window.__meshmorph.state.loads > n || window.__meshmorph.state.error, loads, { timeout: 60000 });
    await waitIdle(page);
    const reopened = await page.evaluate(() => window.__meshmorph.state.mesh);
    check(reopened.name === 'horse0-merged.glb' && reopened.weldedVertices === pageResult.positions.length / 3, `reopened ${JSON.stringify({ name: reopened.name, v: reopened.weldedVertices })}`);
    const info = await page.textContent('#info');
    check(/boundary loops: 0/.test(info), `the reopened mesh is not closed: ${info.slice(0, 400)}`);
    await nextFrame(page);
    await shot(page, 'merge-6-glb-reopened');
    await page.click('#jobs button[data-job="merge"]');
    await nextFrame(page);
    check(pageErrors.length === errorsBefore, `uncaught page errors: ${pageErrors.slice(errorsBefore).join(' | ')}`);
  });

  it('merge: errors are readable (keys out of order, a closed source, a spec of other meshes)', async ({ page }) => {
    await openExample(page);
    await pickExampleKeys(page);
    // A third pair out of order: target between the two keys going one way, source the other.
    const { tloop, sloop } = await page.evaluate(() => {
      const { merge } = window.__meshmorph.state;
      return { tloop: merge.target.loops[0], sloop: merge.source.loops[0] };
    });
    check(tloop > 10 && sloop > 10, 'loops too short');
    const loops = await page.evaluate(() => window.__meshmorph.hooks.mergeLoops());
    const { target_keys: tk, source_keys: sk } = exampleSpec.pairs[0];
    // Target: the vertex half-way between the keys one way; source: half-way the other way
    // round its loop (where the right partner is not).
    const between = (loop, a, b, forward) => {
      const i = loop.indexOf(a);
      const j = loop.indexOf(b);
      const n = loop.length;
      const d = forward ? (j - i + n) % n : (i - j + n) % n;
      return loop[forward ? (i + Math.floor(d / 2)) % n : (j + Math.floor(d / 2)) % n];
    };
    const t3 = between(loops.target[0], tk[0], tk[1], true);
    const s3a = between(loops.source[0], sk[0], sk[1], true);
    const s3b = between(loops.source[0], sk[0], sk[1], false);
    // One of the two source choices is out of order; the page finds which.
    let wrong = null;
    for (const s3 of [s3a, s3b]) {
      const problem = await page.evaluate(([t, s]) => window.__meshmorph.hooks.mergeProblem([...window.__meshmorph.state.merge.pairs, [t, s]]), [t3, s3]);
      if (problem) wrong = s3;
    }
    check(wrong !== null, 'no out-of-order choice found');
    await clickKey(page, 'target', t3);
    const m = await clickKey(page, 'source', wrong);
    check(m.pairs.length === 3 && /out of order/.test(m.problem ?? ''), `expected an out-of-order problem: ${JSON.stringify({ pairs: m.pairs, problem: m.problem })}`);
    check(await page.isVisible('#mg-problem'), 'the problem is not shown');
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.click('#mg-run');
    await page.waitForFunction(() => window.__meshmorph.state.error, null, { timeout: 10000 });
    const error = await page.evaluate(() => window.__meshmorph.state.error);
    check(/out of order/.test(error.message) && (await page.textContent('#error')).includes('out of order'), `error ${JSON.stringify(error)}`);
    await shot(page, 'merge-7-error-order');
    await page.click('#error-close');
    await page.click('table.merge-keys tbody tr[data-index="2"] button.delete');
    check((await mergeState(page)).pairs.length === 2 && !(await mergeState(page)).problem, 'deleting pair 3 did not fix it');

    // The core's own message: a spec whose keys are on the loop but the order check is the
    // core's (loaded from a file, bypassing the clicks).
    const badSpec = path.join(shotDir, 'merge-bad-order.json');
    fs.writeFileSync(badSpec, JSON.stringify({ pairs: [{ target_keys: [tk[0], t3, tk[1]], source_keys: [sk[0], wrong, sk[1]] }] }));
    await page.setInputFiles('#mg-load', badSpec);
    await page.waitForFunction(() => window.__meshmorph.state.merge.pairs.length === 3, null, { timeout: 5000 });
    const core = await page.evaluate(async (spec) => {
      const r = window.__meshmorph.client.run('merge', { targetSlot: 'merge-target', sourceSlot: 'merge-source', spec });
      return r.promise.then(() => null, (e) => ({ code: e.code, message: e.message }));
    }, JSON.parse(fs.readFileSync(badSpec, 'utf8')));
    check(core?.code === 'InvalidArgument' && /out of order/.test(core.message), `core error: ${JSON.stringify(core)}`);

    // A spec of other meshes: its vertex numbers are out of range.
    const otherSpec = path.join(shotDir, 'merge-other-meshes.json');
    fs.writeFileSync(otherSpec, JSON.stringify({ pairs: [{ target_keys: [5, 900000], source_keys: [1, 2] }] }));
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.setInputFiles('#mg-load', otherSpec);
    await page.waitForFunction(() => window.__meshmorph.state.error, null, { timeout: 5000 });
    const specError = await page.evaluate(() => window.__meshmorph.state.error);
    check(/900000/.test(specError.message) && /13102 vertices/.test(specError.message), `spec error ${JSON.stringify(specError)}`);
    await page.click('#error-close');

    // A closed source: the step list says to cut it; Merge says what is missing.
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    await page.selectOption('#mg-source-sample', 'horse');
    await page.waitForFunction(() => window.__meshmorph.state.merge.source?.name === 'horse0.ply' || window.__meshmorph.state.error, null, { timeout: 60000 });
    await waitIdle(page);
    const closed = await mergeState(page);
    check(closed.step === 2 && closed.source.loops.length === 0, `closed source: step ${closed.step}`);
    check(/closed/.test(await page.textContent('#mg-steps .current')), 'the step does not say the source is closed');
    const core2 = await page.evaluate(async () => {
      const r = window.__meshmorph.client.run('merge', { targetSlot: 'merge-target', sourceSlot: 'merge-source', spec: { pairs: [{ target_keys: [13035, 8349], source_keys: [1, 2] }] } });
      return r.promise.then(() => null, (e) => ({ code: e.code, message: e.message }));
    });
    check(core2?.code === 'InvalidMesh' && /no boundary/.test(core2.message), `core error: ${JSON.stringify(core2)}`);
    await nextFrame(page);
    await shot(page, 'merge-8-closed-source');
  });

  it('merge: cut tools — a plane and a disk open the closed horse', async ({ page }) => {
    await page.click('#jobs button[data-job="merge"]');
    await page.evaluate(() => { window.__meshmorph.state.error = null; });
    let m = await mergeState(page);
    if (m.target?.name !== 'horse0.ply') {
      await page.selectOption('#mg-target-sample', 'horse');
      await page.waitForFunction(() => window.__meshmorph.state.merge.target?.name === 'horse0.ply' && !window.__meshmorph.state.busy, null, { timeout: 60000 });
      await waitIdle(page);
    }
    // The example's horse is cut at the neck: Undo cut gives the closed horse back.
    await page.click('#mg-cut summary');
    for (let n = (await mergeState(page)).target.cuts.length; n > 0; n = (await mergeState(page)).target.cuts.length) {
      await page.click('#mg-cut-undo'); // n is read before the click: Firefox's click can return after the undo landed
      await page.waitForFunction((k) => window.__meshmorph.state.merge.target.cuts.length < k, n, { timeout: 60000 });
      await waitIdle(page);
    }
    m = await mergeState(page);
    check(m.target.loops.length === 0, 'the horse is not closed?');
    await page.check('input[name="mg-tool"][value="plane"]');
    // Click the target where the view shows its middle (a ray through the centre of its box).
    const box = await page.locator('#view').boundingBox();
    const centre = await page.evaluate(() => window.__meshmorph.hooks.mergeCentreOnScreen('target'));
    let placed = null;
    for (const [dx, dy] of [[0, 0], [0, 0.04], [0, -0.04], [0.03, 0], [-0.03, 0]]) {
      await page.mouse.move(centre.x + box.width * dx, centre.y + box.height * dy, { steps: 3 });
      await page.mouse.down();
      await page.mouse.up();
      placed = await page.evaluate(() => window.__meshmorph.hooks.mergePlane());
      if (placed) break;
    }
    check(placed?.side === 'target', `no plane placed on the target: ${JSON.stringify(placed)}`);
    await nextFrame(page);
    await shot(page, 'merge-9-plane-preview');
    await page.click('#mg-cut-apply');
    await page.waitForFunction(() => window.__meshmorph.state.merge.target?.cuts.length === 1 || window.__meshmorph.state.error, null, { timeout: 60000 });
    await waitIdle(page);
    m = await mergeState(page);
    const cutError = await page.evaluate(() => window.__meshmorph.state.error);
    check(!cutError && m.target.loops.length >= 1, `after the plane cut: ${JSON.stringify(m.target)} ${JSON.stringify(cutError)}`);
    await nextFrame(page);
    await shot(page, 'merge-10-plane-cut');
    // Undo, then a disk.
    await page.click('#mg-cut-undo');
    await page.waitForFunction(() => window.__meshmorph.state.merge.target?.cuts.length === 0, null, { timeout: 60000 });
    await waitIdle(page);
    await page.check('input[name="mg-tool"][value="disk"]');
    for (const [dx, dy] of [[0, 0], [0, 0.04], [0, -0.04], [0.03, 0]]) {
      await page.mouse.move(centre.x + box.width * dx, centre.y + box.height * dy, { steps: 3 });
      await page.mouse.down();
      await page.mouse.up();
      if (await page.isEnabled('#mg-cut-apply')) break;
    }
    await nextFrame(page);
    await shot(page, 'merge-11-disk-preview');
    await page.click('#mg-cut-apply');
    await page.waitForFunction(() => window.__meshmorph.state.merge.target?.cuts.length === 1 || window.__meshmorph.state.error, null, { timeout: 60000 });
    await waitIdle(page);
    m = await mergeState(page);
    check(m.target.loops.length === 1 && m.target.cuts[0].disk, `after the disk cut: ${JSON.stringify(m.target)}`);
    await page.check('input[name="mg-tool"][value=""]');
    await nextFrame(page);
    await shot(page, 'merge-12-disk-cut');
  });

  it('merge: dependent mode — placed source, a brushed fixed handle, the same mesh as the CLI on the saved inputs', async ({ page }) => {
    await openExample(page);
    await pickExampleKeys(page);
    await page.check('input[name="mg-mode"][value="dependent"]');
    await nextFrame(page);
    let m = await mergeState(page);
    check(m.mode === 'dependent' && m.placement.some((v, i) => v !== [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1][i]), 'the source was not placed on the target\'s loop');
    await shot(page, 'merge-13-dependent-placed');
    // Brush a fixed handle on the camel's head: the vertex furthest from the neck loop.
    const tip = await page.evaluate(() => window.__meshmorph.hooks.mergeFarthestSourceVertex());
    let at = await page.evaluate((v) => window.__meshmorph.hooks.mergeVertexOnScreen('source', v), tip);
    check(at.x > 0 && at.y > 0, `tip at ${JSON.stringify(at)}`);
    await page.click('#mg-brush');
    await page.mouse.move(at.x, at.y, { steps: 3 });
    await page.mouse.down();
    await page.mouse.move(at.x + 4, at.y + 3, { steps: 2 });
    await page.mouse.up();
    await page.click('#mg-brush');
    m = await mergeState(page);
    check(m.fixed > 0, 'the brush fixed nothing');
    await nextFrame(page);
    await shot(page, 'merge-14-dependent-fixed');
    await runMerge(page, 1);
    m = await mergeState(page);
    check(m.result.boundaryLoops === 0, `dependent result has ${m.result.boundaryLoops} loops`);
    await shot(page, 'merge-15-dependent-result');
    // The CLI on the spec and the placed source the page saved.
    const specFile = await download(page, '#mg-save');
    const saved = JSON.parse(fs.readFileSync(specFile, 'utf8'));
    check(saved.options?.mode === 'dependent' && saved.fixed?.length === m.fixed, `saved ${JSON.stringify({ options: saved.options, fixed: saved.fixed?.length })}`);
    const sourceFile = await download(page, '#mg-save-source');
    const targetFile = await download(page, '#mg-save-target');
    check(/camelhead-placed\.off$/.test(sourceFile) && /horse0-cut\.off$/.test(targetFile), `file names ${sourceFile} ${targetFile}`);
    const pageResult = await page.evaluate(() => window.__meshmorph.hooks.mergeResult());
    compareWithCli(pageResult, { target: targetFile, source: sourceFile, spec: specFile, label: 'dependent' });
    // Fixed vertices kept their placed positions exactly.
    const kept = await page.evaluate(() => window.__meshmorph.hooks.mergeFixedError());
    check(kept <= 1e-12, `fixed vertices moved by ${kept}`);
  });
}
