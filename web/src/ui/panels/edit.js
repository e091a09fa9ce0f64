// The Edit job: move a part of the loaded mesh with a gizmo and let the implicit Laplacian
// editor (docs/edit.md, worker/ops/edit.js) reshape the rest. A guided step list leads through
//   1 paint the handle(s) (brush: hold B or turn the brush on; Shift erases; New handle adds one)
//   2 optionally paint the fixed part and / or limit the region of interest, then Start editing
//   3 drag the gizmo (translate / rotate / scale) of the chosen handle: previews follow at the
//     worker's pace
//   4 on release the shape is finalized; save the spec (the CLI's JSON) or export a GLB.
// Sets live on the welded mesh (what the core edits; lib/edit-selection.js), the brush paints
// displayed vertices (view/brush.js) and maps them through toWelded. Moves (previews through a
// latest-only pump, finalize, undo / redo) are ui/edit-moves.js.
// The spec sent to editCreate plus the handles' matrices is exactly the spec "Save spec" writes
// (lib/edit-spec.js), so `meshmorph edit --spec` reproduces the page's result.
// State it owns (window.__meshmorph.state.edit): {step, handle, roi, fixed (vertex counts;
// handle: of all handles), handles (vertex count per handle), active (the handle painted / on
// the gizmo), session, matrices (one per handle), drags (ui/edit-moves.js stats), finalized,
// spec (sent to editCreate), saved (last saved spec)}. Test hooks (window.__meshmorph.hooks):
// editGizmoHandle(name) → client {x, y} of a gizmo handle, editPositions() → {raw, welded}.
import { EditSelection } from '../../lib/edit-selection.js';
import { buildSpec, identity, readSpec } from '../../lib/edit-spec.js';
import { grow, shrink, vertexAdjacency, weldedTriangles } from '../../lib/vertex-sets.js';
import { Brush } from '../../view/brush.js';
import { EditGizmo } from '../../view/edit-gizmo.js';
import { handleColor, selectionColors } from '../../view/selection-colors.js';
import { download } from '../download.js';
import { finder, fromHtml } from '../dom.js';
import { EditMoves, sameMatrices } from '../edit-moves.js';
import { OptionsForm } from '../options-form.js';
import { StepList } from '../step-list.js';

const rgb = (c) => `rgb(${c.map((v) => Math.round(255 * v)).join(', ')})`;

const markup = `
<section class="edit">
  <h2>Edit</h2>
  <div id="edit-steps"></div>
  <div class="row">
    <label>Handle <select id="edit-handle" title="The handle the brush paints and the gizmo moves"></select></label>
    <button id="edit-new-handle" type="button" title="Paint another handle (each moves on its own)">New handle</button>
  </div>
  <div id="edit-select">
    <div class="row paint-targets" role="radiogroup" aria-label="Paint">
      <label class="set-handle"><input type="radio" name="edit-target" value="handle" checked /> Handle</label>
      <label class="set-fixed"><input type="radio" name="edit-target" value="fixed" /> Fixed</label>
      <label class="set-roi"><input type="radio" name="edit-target" value="roi" /> Region</label>
    </div>
    <div class="row">
      <button id="edit-brush" type="button" aria-pressed="false" title="Paint with the brush (or hold B); Shift erases">Brush</button>
      <label class="slider row">size <input type="range" id="edit-radius" min="4" max="80" value="24" /></label>
    </div>
    <div class="row">
      <button id="edit-grow" type="button" title="Add the neighbours of the painted set (1 ring)">Grow</button>
      <button id="edit-shrink" type="button" title="Remove the border of the painted set (1 ring)">Shrink</button>
      <button id="edit-clear" type="button" title="Empty the painted set">Clear</button>
    </div>
    <p id="edit-counts" class="hint"></p>
    <button id="edit-start" type="button" data-idle>Start editing</button>
  </div>
  <div id="edit-drag" hidden>
    <div class="row" role="radiogroup" aria-label="Gizmo">
      <label><input type="radio" name="edit-mode" value="translate" checked /> Move (W)</label>
      <label><input type="radio" name="edit-mode" value="rotate" /> Rotate (E)</label>
      <label><input type="radio" name="edit-mode" value="scale" /> Scale (R)</label>
    </div>
    <label class="row">Details
      <select id="edit-features" data-idle title="keep: details keep their size (Eq. 9); scale: they follow the handle's scaling (Eq. 10)">
        <option value="keep">keep their size</option>
        <option value="scale">scale with the handle</option>
      </select>
    </label>
    <div class="row">
      <button id="edit-undo" type="button" data-idle title="Ctrl+Z">Undo</button>
      <button id="edit-redo" type="button" data-idle title="Ctrl+Y">Redo</button>
      <button id="edit-reset" type="button" data-idle title="Put the handle back where it was">Reset</button>
      <button id="edit-stop" type="button" data-idle title="End the session and change the selection">Back to selection</button>
    </div>
  </div>
  <div class="row">
    <button id="edit-save" type="button" data-idle title="The edit as a JSON spec for meshmorph edit --spec">Save spec</button>
    <label class="button file" title="Open a spec this page saved">Load spec…
      <input type="file" id="edit-load" accept=".json,application/json" data-idle />
    </label>
    <button id="edit-export" type="button" data-idle>Export GLB</button>
  </div>
  <div id="edit-options"></div>
</section>`;

export const panel = {
  id: 'edit',
  title: 'Edit',
  create(app) {
    const { state, viewer, client } = app;
    const root = fromHtml(markup);
    const $ = finder(root);
    const edit = {
      step: 0, handle: 0, handles: [0], active: 0, roi: 0, fixed: 0, session: false, matrices: [identity],
      drags: { sent: 0, answered: 0, first: 0, last: 0, roundTripMs: 0, applyMs: 0 }, finalized: 0, spec: null, saved: null,
      restored: 0, // sessions brought back in a replaced worker
    };
    state.edit = edit;

    const steps = new StepList([
      { title: 'Select the handle(s)' },
      { title: 'Fixed part / region (optional)' },
      { title: 'Drag the gizmo' },
      { title: 'Save or export' },
    ]);
    $('edit-steps').append(steps.element);

    // ---- the mesh as the panel sees it
    let topology = null;     // {count, toWelded, triangles, adjacency (lazy), restRaw, restWelded}
    let sets = null;         // EditSelection of the loaded mesh
    let centroids = [];      // per handle, in a session: the rest centroid (the gizmo's pivot)
    let welded = null;       // current welded positions (Float32Array #W·3) after a drag/finalize
    let shown = null;        // the same in the raw layout (what the Edit job shows)
    let shownNormals = null; // its normals (raw layout), from the worker
    let form = null;         // OptionsForm, once the schema arrived
    let visible = false;     // the Edit job is shown

    const brush = new Brush(viewer);
    const gizmo = new EditGizmo(viewer, {
      onChange: (matrix) => { if (edit.session) moves.preview(moves.with(edit.active, matrix)); },
      onRelease: (matrix) => { if (edit.session) moves.commit(moves.with(edit.active, matrix)); },
    });

    function newMesh(mesh) {
      const geometry = viewer.geometry;
      const restRaw = geometry.getAttribute('position').array.slice();
      const count = mesh.weldedVertices;
      const restWelded = new Float64Array(count * 3);
      for (let r = 0; r < mesh.toWelded.length; ++r) {
        const w = mesh.toWelded[r];
        restWelded.set(restRaw.subarray(3 * r, 3 * r + 3), 3 * w);
      }
      topology = { count, toWelded: mesh.toWelded, triangles: weldedTriangles(geometry.index.array, mesh.toWelded), adjacency: null, restRaw, restWelded };
      sets = new EditSelection(count);
      edit.active = 0;
      welded = null;
      endSession({ restore: false });
      refresh();
    }

    const adjacency = () => (topology.adjacency ??= vertexAdjacency(topology.triangles, topology.count));
    const target = () => root.querySelector('input[name="edit-target"]:checked').value;

    // ---- showing the state

    function showColors() {
      if (visible && sets) viewer.setColors(selectionColors(sets, topology.toWelded));
    }

    function refresh() {
      const counts = sets ? sets.counts() : { handle: 0, handles: [0], roi: 0, fixed: 0 };
      Object.assign(edit, counts);
      const handleCount = counts.handles.length;
      const picker = $('edit-handle');
      while (picker.options.length > handleCount) picker.remove(picker.options.length - 1);
      for (let h = 0; h < handleCount; ++h) {
        const option = picker.options[h] || picker.appendChild(new Option('', String(h)));
        option.textContent = `${h + 1} · ${edit.handles[h]} vertices`;
        option.style.color = rgb(handleColor(h));
      }
      picker.value = String(edit.active);
      picker.style.borderColor = rgb(handleColor(edit.active));
      root.querySelector('.set-handle').style.borderColor = rgb(handleColor(edit.active));
      $('edit-new-handle').hidden = edit.session;
      $('edit-counts').textContent = sets
        ? `handles ${edit.handle} · fixed ${edit.fixed} · region ${edit.roi || 'whole part (default)'} (welded vertices)`
        : 'Load a mesh first (Mesh tab).';
      $('edit-select').hidden = edit.session;
      $('edit-drag').hidden = !edit.session;
      $('edit-brush').setAttribute('aria-pressed', String(brushOn));
      if (!state.mesh) {
        edit.step = 0;
        steps.set(0, 'Load a mesh in the Mesh tab.');
      } else if (!edit.session && !edit.handle) {
        edit.step = 0;
        steps.set(0, 'Turn on the Brush (or hold B) and paint the part you want to move; New handle adds another.');
      } else if (!edit.session) {
        edit.step = 1;
        steps.set(1, 'Optionally paint the Fixed part (or a Region), then press Start editing.');
      } else if (edit.finalized === 0) {
        edit.step = 2;
        steps.set(2, `Drag an arrow, ring or box of the gizmo (W / E / R: move, rotate, scale)${sets.handleCount > 1 ? '; Handle picks the one it moves' : ''}.`);
      } else {
        edit.step = 3;
        steps.set(3, 'Save spec or Export GLB — or keep dragging; Undo goes back.');
      }
    }

    // ---- the brush

    let brushOn = false;   // the Brush button
    let keyHeld = false;   // B held
    let painting = false;
    let pointer = null;    // last client position over the canvas
    const brushActive = () => visible && !edit.session && Boolean(sets) && (brushOn || keyHeld);

    function updateBrush() {
      const active = brushActive();
      viewer.controls.enabled = !active && !gizmo.dragging;
      if (active && pointer) brush.showCursor(pointer.x, pointer.y, { erase: pointer.shift });
      else brush.showCursor(null);
      refresh();
    }

    let lastPainted = null; // where the stroke painted last: a fast move paints the way between
    function paintAt(x, y, erase) {
      const vertices = brush.verticesAlong(lastPainted ?? { x, y }, { x, y }).map((r) => topology.toWelded[r]);
      lastPainted = { x, y };
      if (sets.paint(vertices, target(), edit.active, erase)) {
        showColors();
        refresh();
      }
    }

    const canvas = viewer.renderer.domElement;
    canvas.addEventListener('pointerdown', (e) => {
      if (!brushActive() || e.button !== 0) return;
      painting = true;
      canvas.setPointerCapture(e.pointerId);
      pointer = { x: e.clientX, y: e.clientY, shift: e.shiftKey };
      lastPainted = null;
      paintAt(e.clientX, e.clientY, e.shiftKey);
    });
    canvas.addEventListener('pointermove', (e) => {
      pointer = { x: e.clientX, y: e.clientY, shift: e.shiftKey };
      if (!brushActive()) return;
      brush.showCursor(e.clientX, e.clientY, { erase: e.shiftKey });
      if (painting) paintAt(e.clientX, e.clientY, e.shiftKey);
    });
    const stopPainting = () => { painting = false; };
    canvas.addEventListener('pointerup', stopPainting);
    canvas.addEventListener('pointercancel', stopPainting);
    canvas.addEventListener('pointerleave', () => {
      pointer = null;
      brush.showCursor(null);
    });

    const typing = (e) => e.target instanceof HTMLElement && /^(INPUT|SELECT|TEXTAREA)$/.test(e.target.tagName) && e.target.type !== 'radio';
    window.addEventListener('keydown', (e) => {
      if (!visible || typing(e)) return;
      const key = e.key.toLowerCase();
      if (key === 'b' && !e.repeat && !edit.session) {
        keyHeld = true;
        updateBrush();
      } else if (edit.session && !e.ctrlKey && !e.metaKey && 'wer'.includes(key) && key.length === 1) {
        setMode({ w: 'translate', e: 'rotate', r: 'scale' }[key]);
      } else if (edit.session && (e.ctrlKey || e.metaKey) && key === 'z') {
        e.preventDefault();
        if (e.shiftKey) redo(); else undo();
      } else if (edit.session && (e.ctrlKey || e.metaKey) && key === 'y') {
        e.preventDefault();
        redo();
      }
    });
    window.addEventListener('keyup', (e) => {
      if (e.key.toLowerCase() === 'b' && keyHeld) {
        keyHeld = false;
        painting = false;
        updateBrush();
      }
    });

    $('edit-brush').addEventListener('click', () => {
      brushOn = !brushOn;
      updateBrush();
    });
    $('edit-radius').addEventListener('input', () => {
      brush.setRadius(Number($('edit-radius').value));
      if (brushActive() && pointer) brush.showCursor(pointer.x, pointer.y);
    });
    brush.setRadius(Number($('edit-radius').value));

    // Grow / shrink / clear the painted set (for handles: the active one).
    function changeSet(fn) {
      if (!sets) return;
      sets.change(target(), edit.active, fn);
      showColors();
      refresh();
    }
    $('edit-grow').addEventListener('click', () => changeSet((s) => grow(s, adjacency())));
    $('edit-shrink').addEventListener('click', () => changeSet((s) => shrink(s, adjacency())));
    $('edit-clear').addEventListener('click', () => changeSet((s) => s.fill(0)));

    $('edit-new-handle').addEventListener('click', () => {
      if (!sets || edit.session) return;
      edit.active = sets.addHandle();
      root.querySelector('input[name="edit-target"][value="handle"]').checked = true;
      refresh();
    });
    $('edit-handle').addEventListener('change', () => {
      edit.active = Number($('edit-handle').value);
      if (edit.session) attachGizmo();
      refresh();
    });

    // ---- the session

    const features = () => $('edit-features').value;
    // The spec of the current selection and options; in a session, of the session's selection
    // and options (changes wait for the next Start editing) with the current features mode.
    const currentSpec = (matrices) => {
      const base = edit.session ? readSpec(edit.spec) : { ...sets.lists(), options: form ? form.values() : {} };
      return buildSpec({ ...base, matrices, features: features() });
    };

    // The gizmo on the active handle: pivot at its rest centroid, moved by its current matrix.
    function attachGizmo() {
      gizmo.attach(centroids[edit.active]);
      gizmo.setMatrix(moves.current[edit.active]);
      if (!visible) gizmo.hide();
    }
    // The CLI finalizes only with method "implicit" (the naive baseline has no second step).
    const finalizes = () => (edit.spec?.options?.method ?? 'implicit') === 'implicit';

    function show(result) {
      welded = result.buffers.positions;
      shown = result.buffers.rawPositions;
      shownNormals = result.buffers.rawNormals;
      if (visible) viewer.setPositions(shown, shownNormals);
    }

    const moves = new EditMoves({
      client,
      runOp: (...args) => app.runOp(...args),
      mode: features,
      finalizes,
      onPositions: show,
      onSettled(matrices) {
        edit.matrices = matrices;
        edit.finalized = moves.finalized;
        refresh();
      },
      onError: (e) => app.showError(e),
    });
    edit.drags = moves.stats;

    async function step(delta) {
      if (!edit.session || gizmo.dragging) return;
      const matrices = await moves.step(delta);
      if (matrices) gizmo.setMatrix(matrices[edit.active]);
    }
    const undo = () => step(-1);
    const redo = () => step(+1);

    function setMode(mode) {
      gizmo.setMode(mode);
      const radio = root.querySelector(`input[name="edit-mode"][value="${mode}"]`);
      if (radio) radio.checked = true;
    }

    // spec: the session's spec (a restored session's); by default the current selection's.
    async function startSession(matrices = null, sessionSpec = null) {
      if (!sets || !sets.counts().handle) {
        app.showError({ code: 'InvalidArgument', message: 'paint a handle first (step 1): the edit needs at least one handle vertex' });
        return false;
      }
      endSession({ restore: true });
      edit.active = sets.compact(edit.active);
      refresh();
      const spec = sessionSpec ?? currentSpec(null);
      const result = await app.runOp('Preparing the edit', 'editCreate', { spec });
      if (!result) return false;
      edit.spec = spec;
      edit.session = true;
      edit.finalized = 0;
      moves.reset(sets.handleCount);
      edit.matrices = moves.current;
      edit.drags = moves.stats;
      brushOn = false;
      keyHeld = false;
      // Each handle's gizmo pivots about the centroid of its rest positions (the spec's default).
      centroids = Array.from({ length: sets.handleCount }, (_, h) => {
        const handle = sets.handleMembers(h);
        const c = [0, 0, 0];
        for (const w of handle) for (let k = 0; k < 3; ++k) c[k] += topology.restWelded[3 * w + k] / handle.length;
        return c;
      });
      attachGizmo();
      updateBrush();
      app.setStatus(`editing: ${result.info.handles.join(' + ')} handle vertices, ${result.info.stats.free_vertices} free · prepared in ${result.info.milliseconds} ms`);
      if (matrices && !sameMatrices(matrices, moves.current)) {
        gizmo.setMatrix(matrices[edit.active]);
        await moves.commit(matrices);
      }
      return true;
    }

    function endSession({ restore = true } = {}) {
      if (edit.session) client.run('editDispose', {}).promise.catch(() => {});
      edit.session = false;
      edit.finalized = 0;
      edit.matrices = [identity];
      moves.reset(1);
      edit.drags = moves.stats;
      gizmo.detach();
      if (restore && topology && shown) viewer.setPositions(topology.restRaw.slice());
      welded = null;
      shown = null;
    }

    $('edit-start').addEventListener('click', () => startSession());
    $('edit-stop').addEventListener('click', () => {
      endSession();
      refresh();
      updateBrush();
    });
    $('edit-undo').addEventListener('click', undo);
    $('edit-redo').addEventListener('click', redo);
    $('edit-reset').addEventListener('click', () => {
      if (!edit.session || gizmo.dragging) return;
      gizmo.setMatrix(identity);
      moves.commit(moves.current.map(() => identity));
    });
    $('edit-features').addEventListener('change', () => { if (edit.session) moves.settle(); });
    for (const radio of root.querySelectorAll('input[name="edit-mode"]')) radio.addEventListener('change', () => setMode(radio.value));

    // ---- save, load, export

    $('edit-save').addEventListener('click', () => {
      if (!sets || !sets.counts().handle) {
        app.showError({ code: 'InvalidArgument', message: 'paint a handle first: a spec needs at least one handle vertex' });
        return;
      }
      const spec = currentSpec(edit.session ? moves.current : null);
      edit.saved = spec;
      const stem = state.mesh.name.replace(/\.[^.]*$/, '');
      download(new TextEncoder().encode(`${JSON.stringify(spec, null, 1)}\n`), `${stem}.edit.json`, 'application/json');
    });

    $('edit-load').addEventListener('change', async () => {
      const file = $('edit-load').files[0];
      $('edit-load').value = '';
      if (!file || !topology) return;
      let spec;
      try {
        spec = readSpec(JSON.parse(await file.text()));
        sets = EditSelection.fromLists(spec, topology.count);
        edit.active = 0;
      } catch (e) {
        app.showError(e instanceof SyntaxError ? { code: 'ParseError', message: `${file.name}: ${e.message}` } : e);
        return;
      }
      $('edit-features').value = spec.features;
      form?.setValues(spec.options);
      endSession();
      showColors();
      refresh();
      await startSession(spec.matrices);
    });

    $('edit-export').addEventListener('click', async () => {
      if (!state.mesh) return;
      const buffers = welded ? { positions: welded } : {};
      const result = await app.runOp('Exporting GLB', 'export', { format: 'glb' }, buffers);
      if (!result) return;
      download(result.buffers.bytes, result.info.fileName.replace(/\.glb$/, '-edited.glb'), 'model/gltf-binary');
    });

    // ---- wiring

    app.on('ready', async () => {
      try {
        const result = await client.run('optionSchema', { job: 'edit' }).promise;
        // "features" has its own control (Details), applied at every finalize.
        // The op answers {job, summary, options: [...]} (wasm/bind_app.cpp).
        const options = Array.isArray(result.info) ? result.info : result.info.options;
        form = new OptionsForm(options.filter((o) => o.name !== 'features'), { title: 'Options (used at Start editing)' });
        $('edit-options').append(form.element);
      } catch (e) {
        app.showError(e);
      }
      refresh();
    });
    app.on('mesh', (mesh) => newMesh(mesh));
    // A replaced worker has the meshes again but not the edit session: the same edit is prepared
    // in it and its steps come back (the current one settled, undo / redo as they were). A
    // session whose preparation was cancelled never started, so nothing comes back then.
    app.on('restarted', async () => {
      if (!edit.session) return;
      // Back to the last step that was settled: a step still settling may be what the cancel
      // stopped, or what the worker died of.
      const spec = edit.spec, history = moves.history, active = edit.active;
      const settled = history.map((_, i) => i).filter((i) => sameMatrices(history[i], edit.matrices));
      const at = settled.length ? settled.reduce((a, b) => (Math.abs(b - moves.at) < Math.abs(a - moves.at) ? b : a)) : 0;
      edit.session = false; // nothing to dispose in the new worker
      endSession();
      refresh();
      updateBrush();
      edit.active = active;
      if (!(await startSession(null, spec))) return;
      if (!(await moves.restore(history, at))) return;
      gizmo.setMatrix(moves.current[edit.active]);
      edit.matrices = moves.current;
      edit.restored += 1;
      app.setStatus('editing: the session was prepared again in the new worker, with its steps');
      refresh();
    });
    app.on('job', (job) => {
      const was = visible;
      visible = job === 'edit';
      // Other jobs work on the loaded mesh, so they show it; the edit comes back with the job.
      if (visible) {
        showColors();
        if (shown) viewer.setPositions(shown.slice(), shownNormals?.slice());
        if (edit.session) gizmo.show();
      } else if (was) {
        viewer.setColors(null);
        if (shown) viewer.setPositions(topology.restRaw.slice());
        gizmo.hide();
        keyHeld = false;
        brushOn = false;
      }
      updateBrush();
    });
    app.hooks.editGizmoHandle = (name) => (edit.session ? gizmo.handleOnScreen(name) : null);
    app.hooks.editPositions = () => ({
      raw: Array.from(viewer.geometry.getAttribute('position').array),
      welded: welded ? Array.from(welded) : null,
    });
    refresh();
    return root;
  },
};
