// The Merge job: attach a source mesh to a target mesh along a boundary loop of each (paper 001
// Sec. 5; docs/web.md "The Merge job"; worker ops in worker/ops/merge.js). A guided step list
// leads through
//   1 load the target (the mesh that stays)    2 load the source (the part attached to it)
//   3 open the boundaries: each mesh needs a boundary loop (drawn on it; the chosen one bright);
//     a closed mesh is cut open with a plane (click a point; normal from the view or the surface;
//     a gizmo turns and moves it) or a geodesic disk (click a vertex, set the radius)
//   4 key vertex pairs: a click snaps to the nearest boundary vertex on either mesh; target and
//     source alternate; numbered markers on both, a table to select, reorder and delete
//   5 mode and merge: independent (the source may sit anywhere) or dependent (place it with a
//     gizmo, optionally brush fixed handles on it); the merge runs in the worker with progress
//     and Cancel
//   6 the result with its seam and the seam report; save the spec (the JSON `meshmorph merge
//     --spec` reads), the inputs as the page merged them, and the merged mesh as GLB (the
//     target's document with the merged geometry).
// The meshes live in their own worker slots (`slots`); each slot is described by one mergeOpen
// request (file + cuts), marked restoreKey, so a replaced worker gets them back.
// State it owns (window.__meshmorph.state.merge): {step, target, source ({name, weldedVertices,
// faces, loops: [lengths], cuts: [CUT]} or null), loops {target, source} (chosen loop index),
// pairs, pending, selected, problem, mode, placement, fixed (count), tool (null | 'plane' |
// 'disk'), result (info of the last merge) or null, showing ('result' | 'inputs'), runs,
// saved (last saved spec), exports, check (the moved-source check)}. Test hooks
// (window.__meshmorph.hooks): mergeVertexOnScreen(side, welded) → {x, y, visible},
// mergeResult() → {positions, indices} (the merged mesh, doubles) or null, mergePlane() → the
// cut plane {point, normal} in the mesh's coordinates or null.
import * as THREE from 'three';
import { MeshMorphError } from '../../lib/errors.js';
import { bboxDiagonal, edgeDistances, loopFrame, planeRemoves, placeOnLoop, randomSimilarity, seamView } from '../../lib/merge-geometry.js';
import { KeyPairs, buildMergeSpec, keyPairsProblem, minKeys, readMergeSpec } from '../../lib/merge-spec.js';
import { samples } from '../../lib/samples.js';
import { vertexAdjacency } from '../../lib/vertex-sets.js';
import { Brush } from '../../view/brush.js';
import { MergeView, keyColor, sideColors } from '../../view/merge-view.js';
import { attachPointerPicking } from '../../view/pointer-picking.js';
import { download } from '../download.js';
import { finder, fromHtml } from '../dom.js';
import { sampleFiles, userFiles } from '../files.js';
import { OptionsForm } from '../options-form.js';
import { StepList } from '../step-list.js';
import './merge.css';

const slots = { target: 'merge-target', source: 'merge-source' };
const sideNames = ['target', 'source'];
// The bundled pair (data/specs/merge-camelhead-horse.json): the TOSCA horse with its head cut
// off by the plane of that spec's comment, and the camel's head with its open neck.
export const mergeExample = {
  target: { sample: 'horse', cuts: [{ plane: [0, -85, 140, 0, -1, 1], keep: [0, 0, 100] }] },
  source: { sample: 'camelhead', cuts: [] },
};
const fileTypes = '.glb,.gltf,.bin,.obj,.off,.ply,.png,.jpg,.jpeg,.webp';
const fixedColor = [0.36, 0.55, 0.98];
const removedColor = [0.93, 0.33, 0.33];
const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

const markup = `
<section class="merge">
  <h2>Merge</h2>
  <div id="mg-steps"></div>
  <div class="row side-row">
    <label for="mg-target-sample" title="The mesh that stays as it is (left)">Target</label>
    <select id="mg-target-sample" data-idle></select>
    <label class="button file" title="Open a target mesh file">Open…<input type="file" id="mg-target-file" multiple accept="${fileTypes}" data-idle /></label>
  </div>
  <div class="row side-row">
    <label for="mg-source-sample" title="The part attached to the target (right)">Source</label>
    <select id="mg-source-sample" data-idle></select>
    <label class="button file" title="Open a source mesh file">Open…<input type="file" id="mg-source-file" multiple accept="${fileTypes}" data-idle /></label>
  </div>
  <div class="row">
    <button id="mg-example" type="button" data-idle title="The TOSCA horse with its head cut off (target) and the camel's head (source)">Load the example: horse + camel head</button>
  </div>
  <p id="mg-meshes" class="hint"></p>

  <h3>Boundaries</h3>
  <div class="row loop-row">
    <label for="mg-target-loop">Target loop</label>
    <select id="mg-target-loop"></select>
    <button id="mg-target-look" type="button" title="Turn the camera to look into the target's chosen loop">Look</button>
  </div>
  <div class="row loop-row">
    <label for="mg-source-loop">Source loop</label>
    <select id="mg-source-loop"></select>
    <button id="mg-source-look" type="button" title="Turn the camera to look into the source's chosen loop">Look</button>
  </div>
  <div class="row">
    <button id="mg-frame" type="button" title="Frame the camera on the two boundaries (the whole result after a merge)">Frame the seam</button>
  </div>
  <details id="mg-cut" class="cut">
    <summary>Cut a mesh open…</summary>
    <p class="hint">A closed mesh (no boundary) or a boundary in the wrong place: cut it. Choose the tool, click on the mesh, adjust, then press Cut.</p>
    <div class="row" role="radiogroup" aria-label="Cut tool">
      <label><input type="radio" name="mg-tool" value="plane" /> Plane</label>
      <label><input type="radio" name="mg-tool" value="disk" /> Disk</label>
      <label><input type="radio" name="mg-tool" value="" checked /> Off</label>
    </div>
    <div id="mg-plane-controls" hidden>
      <div class="row" role="radiogroup" aria-label="Plane normal">
        <span class="label">Normal</span>
        <label title="The plane faces the camera"><input type="radio" name="mg-normal" value="view" checked /> view direction</label>
        <label title="The plane is tangent to the surface where you click… turned by 90°: its normal follows the surface"><input type="radio" name="mg-normal" value="surface" /> surface normal</label>
      </div>
      <div class="row" role="radiogroup" aria-label="Plane gizmo">
        <span class="label">Gizmo</span>
        <label><input type="radio" name="mg-plane-mode" value="translate" checked /> move</label>
        <label><input type="radio" name="mg-plane-mode" value="rotate" /> turn</label>
        <button id="mg-flip" type="button" title="Keep the other side">Flip side</button>
      </div>
    </div>
    <div id="mg-disk-controls" hidden>
      <label class="slider row">radius <input type="range" id="mg-disk-radius" min="1" max="40" value="8" /> <span id="mg-disk-radius-value" class="hint"></span></label>
    </div>
    <p id="mg-cut-hint" class="hint"></p>
    <div class="row">
      <button id="mg-cut-apply" type="button">Cut</button>
      <button id="mg-cut-undo" type="button" title="Take back the last cut of the mesh the tool is on">Undo cut</button>
    </div>
  </details>

  <h3>Key pairs</h3>
  <p id="mg-key-hint" class="hint"></p>
  <p id="mg-hover" class="pick-hover"></p>
  <div id="mg-table"></div>
  <p id="mg-problem" class="problem" hidden></p>
  <div class="row">
    <button id="mg-keys-clear" type="button">Clear</button>
  </div>

  <h3>Mode</h3>
  <div class="row" role="radiogroup" aria-label="Mode">
    <label title="Sec. 5.1: the source may sit anywhere; only its shape matters"><input type="radio" name="mg-mode" value="independent" checked /> independent</label>
    <label title="Sec. 5.2: you place the source; only a band near the seam deforms"><input type="radio" name="mg-mode" value="dependent" /> dependent</label>
  </div>
  <div id="mg-dependent" hidden>
    <div class="row" role="radiogroup" aria-label="Placement gizmo">
      <label><input type="radio" name="mg-place-mode" value="translate" checked /> move</label>
      <label><input type="radio" name="mg-place-mode" value="rotate" /> turn</label>
      <label><input type="radio" name="mg-place-mode" value="scale" /> scale</label>
    </div>
    <div class="row">
      <button id="mg-place" type="button" title="Put the source's loop onto the target's (centre, size, first key pair)">Place on the target's loop</button>
      <button id="mg-place-reset" type="button" title="The source where its file puts it">Reset</button>
    </div>
    <div class="row">
      <button id="mg-brush" type="button" aria-pressed="false" title="Paint source vertices that must not move (Shift erases)">Brush fixed handles</button>
      <label class="slider row">size <input type="range" id="mg-brush-radius" min="4" max="80" value="20" /></label>
      <button id="mg-fixed-clear" type="button">Clear</button>
    </div>
    <p id="mg-fixed-count" class="hint"></p>
  </div>
  <div id="mg-options"></div>
  <div class="row">
    <button id="mg-run" type="button" data-idle>Merge</button>
  </div>

  <div id="mg-result" hidden>
    <h3>Result</h3>
    <div class="row" role="radiogroup" aria-label="Show">
      <label><input type="radio" name="mg-show" value="result" checked /> merged</label>
      <label><input type="radio" name="mg-show" value="inputs" /> inputs</label>
      <label><input type="checkbox" id="mg-seam" checked /> seam</label>
    </div>
    <dl id="mg-report" class="metrics"></dl>
    <div class="row">
      <button id="mg-check" type="button" data-idle title="Merge again with the source moved, turned and scaled at random: the independent mode gives the same mesh (the paper's Fig. 1)">Move the source at random and merge again</button>
    </div>
    <p id="mg-check-out" class="hint"></p>
  </div>
  <h3>Files</h3>
  <div class="row">
    <button id="mg-save" type="button" title="The spec for meshmorph merge --spec (key pairs, fixed handles, options)">Save spec</button>
    <label class="button file" title="Open a merge spec (e.g. one saved here)">Load spec…
      <input type="file" id="mg-load" accept=".json,application/json" data-idle />
    </label>
    <button id="mg-export" type="button" title="The merged mesh in the target's document (materials, nodes kept)">Download GLB</button>
  </div>
  <div class="row">
    <button id="mg-save-target" type="button" title="The target as the page merges it (after cuts), full precision">Save target (.off)</button>
    <button id="mg-save-source" type="button" title="The source as the page merges it (after cuts and placement), full precision">Save source (.off)</button>
  </div>
  <p id="mg-files-hint" class="hint"></p>
</section>`;

const fixed = (v, digits = 3) => (Number.isFinite(v) ? Number(v.toPrecision(digits)).toString() : '–');
const stem = (name) => name.replace(/^.*[\\/]/, '').replace(/\.[^.]*$/, '');
const cutCommand = (cut) => (cut.plane ? `--plane ${cut.plane.map((v) => fixed(v, 12)).join(' ')}${cut.keep ? ` --keep ${cut.keep.map((v) => fixed(v, 12)).join(' ')}` : ''}` : `--disk ${cut.disk[0]} ${fixed(cut.disk[1], 12)}`);

export const panel = {
  id: 'merge',
  title: 'Merge',
  create(app) {
    const { state, viewer, client } = app;
    const root = fromHtml(markup);
    const $ = finder(root);
    const merge = {
      step: 0, target: null, source: null, loops: { target: -1, source: -1 }, pairs: [], pending: null, selected: -1,
      problem: null, mode: 'independent', placement: identity, fixed: 0, tool: null, result: null, showing: 'result',
      runs: 0, saved: null, exports: 0, check: null,
    };
    state.merge = merge;

    const steps = new StepList([
      { title: 'Load the target (the mesh that stays)' },
      { title: 'Load the source (the part to attach)' },
      { title: 'Open and choose the boundaries' },
      { title: 'Pick key pairs on the two boundaries' },
      { title: 'Choose the mode and merge' },
      { title: 'Look at the seam, save, download' },
    ]);
    $('mg-steps').append(steps.element);

    const view = new MergeView(viewer);
    const keys = new KeyPairs();
    // Per side: {files (to reopen with other cuts), cuts, info, welded (Float64 #W·3), indices
    // (welded), adjacency (lazy), rawPositions (displayed, Float32)}.
    const meshes = { target: null, source: null };
    let fixedSet = null;   // Uint8Array over the source's welded vertices
    let result = null;     // {positions: Float64Array, indices: Uint32Array} of the last merge
    let form = null;
    let visible = false;
    let plane = null;      // {side, point: Vector3, normal: Vector3} (local to the side) while the plane tool is placed
    let disk = null;       // {side, welded}
    let brushOn = false;

    // ---- the state shown

    const chosenLoop = (side) => (meshes[side] && merge.loops[side] >= 0 ? meshes[side].info.loops[merge.loops[side]] : null);
    const inputsReady = () => Boolean(meshes.target && meshes.source);

    function refresh() {
      merge.pairs = keys.pairs.map((p) => [...p]);
      merge.pending = keys.pending ? { ...keys.pending } : null;
      if (merge.selected >= keys.pairs.length) merge.selected = -1;
      merge.problem = inputsReady() ? keyPairsProblem(keys.pairs, chosenLoop('target'), chosenLoop('source')) : null;
      merge.fixed = fixedSet ? fixedSet.reduce((n, v) => n + v, 0) : 0;

      for (const side of sideNames) {
        const select = $(`mg-${side}-loop`);
        const loops = meshes[side]?.info.loops ?? [];
        select.replaceChildren(...(loops.length
          ? [new Option('— click near a loop —', '-1'), ...loops.map((l, i) => new Option(`loop ${i} · ${l.length} vertices`, String(i)))]
          : [new Option(meshes[side] ? 'none: the mesh is closed — cut it open' : '—', '-1')]));
        select.value = String(merge.loops[side]);
        select.disabled = loops.length < 2;
        $(`mg-${side}-look`).disabled = merge.loops[side] < 0;
      }

      const loopsMissing = sideNames.filter((s) => meshes[s] && meshes[s].info.loops.length === 0);
      const unchosen = sideNames.filter((s) => meshes[s] && meshes[s].info.loops.length > 0 && merge.loops[s] < 0);
      const n = keys.pairs.length;
      if (!meshes.target) {
        merge.step = 0;
        steps.set(0, 'Pick a target under Target (or Load the example): the mesh that stays as it is.');
      } else if (!meshes.source) {
        merge.step = 1;
        steps.set(1, 'Pick a source under Source: the part that gets attached to the target.');
      } else if (loopsMissing.length || unchosen.length) {
        merge.step = 2;
        steps.set(2, loopsMissing.length
          ? `The ${loopsMissing.join(' and the ')} ${loopsMissing.length > 1 ? 'are' : 'is'} closed: open “Cut a mesh open…”, choose Plane or Disk, click on the mesh, then Cut.`
          : `The ${unchosen.join(' and the ')} has several loops: click near the one to merge (or pick it under Boundaries).`);
      } else if (n < minKeys || merge.problem || keys.pending) {
        merge.step = 3;
        steps.set(3, keys.pending
          ? `Now click the matching point on the ${keys.pending.side === 'target' ? 'source' : 'target'}'s yellow loop (pair ${n + 1}).`
          : merge.problem && n >= minKeys
            ? `Fix the pairs: ${merge.problem}.`
            : `Click a point on the target's yellow loop, then the matching point on the source's (${n} of at least ${minKeys} pairs).`);
      } else if (!merge.result) {
        merge.step = 4;
        steps.set(4, merge.mode === 'dependent'
          ? 'Place the source with the gizmo (or Place on the target\'s loop), optionally brush fixed handles, then press Merge.'
          : `${n} key pairs. Press Merge (or choose the dependent mode to place the source yourself).`);
      } else {
        merge.step = 5;
        steps.set(5, 'Toggle merged / inputs and the seam, read the report; Save spec for the CLI, Download GLB.');
      }

      $('mg-meshes').textContent = sideNames.filter((s) => meshes[s]).map((s) => {
        const { info, cuts } = meshes[s];
        return `${s}: ${info.name}${cuts.length ? ` (cut ${cuts.length}×)` : ''}, ${info.weldedVertices} vertices, ${info.loops.length} boundary loop${info.loops.length === 1 ? '' : 's'}`;
      }).join(' · ');
      let hint;
      if (!inputsReady()) hint = 'Load both meshes first.';
      else if (loopsMissing.length) hint = 'Each mesh needs an open boundary to merge along.';
      else hint = `${n} pair${n === 1 ? '' : 's'}. A click snaps to the nearest boundary vertex (the yellow loop of each mesh); click the target's, then the source's matching one. Keys go in the same direction round both loops.`;
      $('mg-key-hint').textContent = hint;
      const problem = $('mg-problem');
      problem.hidden = !merge.problem || n < minKeys;
      problem.textContent = merge.problem ? `⚠ ${merge.problem}` : '';

      showTable();
      view.showKeys(keys.pairs, keys.pending, merge.selected);
      $('mg-keys-clear').disabled = n === 0 && !keys.pending;
      $('mg-dependent').hidden = merge.mode !== 'dependent';
      $('mg-brush').setAttribute('aria-pressed', String(brushOn));
      $('mg-fixed-count').textContent = `${merge.fixed} fixed source vertices (blue) — they keep their place; only a band of roi_width near the seam deforms.`;
      $('mg-result').hidden = !merge.result;
      $('mg-check').hidden = merge.mode !== 'independent';
      const haveKeys = n >= minKeys;
      $('mg-save').disabled = !haveKeys;
      $('mg-export').disabled = !result;
      $('mg-save-target').disabled = !meshes.target;
      $('mg-save-source').disabled = !meshes.source;
      const moved = merge.mode === 'dependent' && merge.placement.some((v, i) => v !== identity[i]);
      const cut = sideNames.some((s) => meshes[s]?.cuts.length);
      $('mg-files-hint').textContent = cut || moved
        ? `The CLI needs the inputs as merged here: ${cut ? 'the saved spec names the cuts (meshmorph cut), or' : ''} save the ${[cut && 'cut', moved && 'placed'].filter(Boolean).join(' / ')} meshes with the buttons above and run meshmorph merge --target T.off --source S.off --spec SPEC.`
        : 'meshmorph merge --target T --source S --spec SPEC --out OUT.glb gives the same mesh.';
      refreshCut();
    }

    // ---- the key table: number (marker colour), target, source, ↑ ↓ ×

    const table = document.createElement('table');
    table.className = 'landmarks merge-keys';
    table.innerHTML = '<thead><tr><th>#</th><th>target</th><th>source</th><th></th></tr></thead><tbody></tbody>';
    $('mg-table').append(table);
    const rgb = (c) => `rgb(${c.map((v) => Math.round(255 * v)).join(', ')})`;
    function button(text, title, onClick, disabled = false) {
      const b = document.createElement('button');
      b.type = 'button';
      b.className = 'pair-delete';
      b.textContent = text;
      b.title = title;
      b.disabled = disabled;
      b.addEventListener('click', (e) => {
        e.stopPropagation();
        onClick();
      });
      return b;
    }
    function showTable() {
      const body = table.querySelector('tbody');
      body.replaceChildren();
      const cell = (text) => Object.assign(document.createElement('td'), { textContent: text });
      keys.pairs.forEach(([t, s], i) => {
        const row = document.createElement('tr');
        row.dataset.index = String(i);
        row.classList.toggle('selected', i === merge.selected);
        const number = cell(String(i + 1));
        number.className = 'pair-number';
        number.style.background = rgb(keyColor(i));
        const actions = document.createElement('td');
        actions.className = 'pair-actions';
        actions.append(
          button('↑', `Move pair ${i + 1} up`, () => reorder(i, -1), i === 0),
          button('↓', `Move pair ${i + 1} down`, () => reorder(i, +1), i === keys.pairs.length - 1),
          button('×', `Delete pair ${i + 1}`, () => { keys.remove(i); merge.selected = -1; changed(); }),
        );
        actions.lastChild.classList.add('delete');
        row.append(number, cell(String(t)), cell(String(s)), actions);
        row.addEventListener('click', () => { merge.selected = i === merge.selected ? -1 : i; refresh(); });
        body.append(row);
      });
      if (keys.pending) {
        const row = document.createElement('tr');
        row.className = 'pending';
        row.append(cell(String(keys.pairs.length + 1)), cell(keys.pending.side === 'target' ? String(keys.pending.vertex) : '…'),
          cell(keys.pending.side === 'source' ? String(keys.pending.vertex) : '…'), cell(''));
        body.append(row);
      }
      table.hidden = keys.pairs.length === 0 && !keys.pending;
    }
    function reorder(i, delta) {
      merge.selected = keys.move(i, delta);
      changed();
    }

    // Something the result depends on changed: the result goes; the source is shown where the
    // keys now put it.
    function changed() {
      if (result) clearResult();
      arrange();
      refresh();
    }

    // The arrangement of the two meshes: dependent mode — the source where the person placed it;
    // independent mode with both loops chosen — the source turned and scaled as it will attach
    // (its first key on the target's first key), pulled out of the target's opening, seen from
    // the side; otherwise side by side.
    function arrange({ frame = false } = {}) {
      const t = chosenLoop('target');
      const s = chosenLoop('source');
      let direction = null;
      const seamFrame = t && s ? seamView(loopFrame(meshes.target.welded, t).outward) : null;
      view.setOrientation(seamFrame);
      if (seamFrame) {
        // The seam across the screen, seen a little from above and from the source's side,
        // so the target's opening shows as a ring rather than edge-on.
        direction = [0.55, 0.35, 1];
      } else if (t) {
        const { outward } = loopFrame(meshes.target.welded, t);
        const look = [0.35, 0.25, 1];
        const along = look[0] * outward[0] + look[1] * outward[1] + look[2] * outward[2];
        direction = look.map((v, k) => v - along * outward[k] + 0.25 * outward[k]);
      }
      if (merge.mode === 'dependent' && t && s) {
        view.setArrangement('placed', { viewDirection: direction, frame });
      } else if (t && s) {
        const m = placeOnLoop(meshes.target.welded, t, meshes.source.welded, s, keys.pairs[0] ?? null);
        const { outward, length } = loopFrame(meshes.target.welded, t);
        const gap = (1.3 * length) / (2 * Math.PI);
        for (let k = 0; k < 3; ++k) m[12 + k] += gap * outward[k];
        view.setExploded(m);
        view.setArrangement('exploded', { viewDirection: direction, frame });
      } else {
        view.setArrangement('apart', { frame });
      }
    }

    // ---- colours of the inputs: cut preview (red: removed) and fixed handles (blue)

    function showColors(side) {
      const m = meshes[side];
      if (!m) return;
      let removed = null;
      if (plane && plane.side === side) {
        removed = planeRemoves(m.welded, plane.point.toArray(), plane.normal.toArray());
      } else if (disk && disk.side === side) {
        const radius = diskRadius(side);
        const d = edgeDistances(m.welded, adjacency(side), disk.welded, radius);
        removed = Uint8Array.from(d, (x) => (x < radius ? 1 : 0));
      }
      const fixedHere = side === 'source' && merge.mode === 'dependent' && fixedSet && fixedSet.some(Boolean) ? fixedSet : null;
      if (!removed && !fixedHere) {
        view.setColors(side, null);
        return;
      }
      const toWelded = view.sides[side].toWelded;
      const colors = new Float32Array(toWelded.length * 3);
      for (let r = 0; r < toWelded.length; ++r) {
        const w = toWelded[r];
        const c = removed?.[w] ? removedColor : fixedHere?.[w] ? fixedColor : sideColors[side];
        colors.set(c, 3 * r);
      }
      view.setColors(side, colors);
    }

    function adjacency(side) {
      const m = meshes[side];
      m.adjacency ??= vertexAdjacency(m.indices, m.welded.length / 3);
      return m.adjacency;
    }

    // ---- loading (file + cuts → one mergeOpen request per side)

    async function openSide(side, files, cuts, { label } = {}) {
      const [main] = files;
      const buffers = {};
      for (const f of files) buffers[f.name] = f.bytes.slice();
      const opened = await app.runOp(label || `Loading ${main.name} (${side})`, 'mergeOpen', { slot: slots[side], name: main.name, cuts }, buffers, { restoreKey: `mesh:${slots[side]}` });
      if (!opened) {
        // The worker may have dropped the slot (a failed cut): put the previous state back.
        const previous = meshes[side];
        if (previous) {
          const back = {};
          for (const f of previous.files) back[f.name] = f.bytes.slice();
          await client.run('mergeOpen', { slot: slots[side], name: previous.files[0].name, cuts: previous.cuts }, back, { restoreKey: `mesh:${slots[side]}` }).promise.catch(() => {});
        }
        return false;
      }
      const { buffers: b, info } = opened;
      meshes[side] = { files, cuts, info, welded: b.welded, indices: b.weldedIndices, adjacency: null, rawPositions: b.positions };
      merge[side] = { name: info.name, weldedVertices: info.weldedVertices, faces: info.faces, loops: info.loops.map((l) => l.length), cuts };
      view.setMesh(side, b, info.loops);
      merge.loops[side] = view.sides[side].chosenLoop;
      if (side === 'source') {
        fixedSet = new Uint8Array(info.weldedVertices);
        merge.placement = identity;
        view.setPlacement(identity);
      }
      keys.clear();
      merge.selected = -1;
      if (plane?.side === side) setPlane(null);
      if (disk?.side === side) disk = null;
      clearResult();
      showColors(side);
      if (merge.mode === 'dependent' && side === 'source') placeSource();
      arrange({ frame: true });
      app.setStatus(`${side}: ${info.name}${cuts.length ? `, cut ${cuts.length}×` : ''} — ${info.weldedVertices} vertices, ${info.faces} faces, ${info.loops.length} boundary loop(s) · ${client.runtimeSummary}`);
      refresh();
      return true;
    }

    async function loadSample(side, id, cuts = []) {
      const sample = samples.find((s) => s.id === id);
      if (!sample) return false;
      $(`mg-${side}-sample`).value = id;
      try {
        return await openSide(side, await sampleFiles(sample), cuts);
      } catch (e) {
        app.showError(e);
        return false;
      }
    }

    for (const side of sideNames) {
      const select = $(`mg-${side}-sample`);
      select.add(new Option('— choose —', ''));
      for (const s of samples) select.add(new Option(s.label, s.id));
      select.add(new Option('(your file)', 'file'));
      select.addEventListener('change', () => {
        if (select.value && select.value !== 'file') loadSample(side, select.value);
      });
      const input = $(`mg-${side}-file`);
      input.addEventListener('change', async () => {
        const list = [...input.files]; // a copy: clearing the input empties its FileList
        input.value = '';
        if (!list.length) return;
        try {
          if (await openSide(side, await userFiles(list), [])) select.value = 'file';
        } catch (e) {
          app.showError(e);
        }
      });
      $(`mg-${side}-loop`).addEventListener('change', () => {
        setLoop(side, Number($(`mg-${side}-loop`).value));
      });
      $(`mg-${side}-look`).addEventListener('click', () => lookAt(side));
    }
    $('mg-frame').addEventListener('click', () => view.frameCamera());
    $('mg-example').addEventListener('click', async () => {
      const off = root.querySelector('input[name="mg-tool"][value=""]');
      if (!off.checked) {
        off.checked = true;
        off.dispatchEvent(new Event('change'));
      }
      if (await loadSample('target', mergeExample.target.sample, mergeExample.target.cuts)) {
        await loadSample('source', mergeExample.source.sample, mergeExample.source.cuts);
      }
    });
    app.onDrop?.('merge', {
      describe: (x) => `Drop a mesh to open it as the ${dropSide(x)}`,
      drop: async (list, x) => {
        const side = dropSide(x);
        try {
          if (await openSide(side, await userFiles(list), [])) $(`mg-${side}-sample`).value = 'file';
        } catch (e) {
          app.showError(e);
        }
      },
    });
    function dropSide(clientX) {
      const rect = viewer.renderer.domElement.getBoundingClientRect();
      return clientX < rect.left + rect.width / 2 ? 'target' : 'source';
    }

    function setLoop(side, loop) {
      if (merge.loops[side] === loop) return;
      merge.loops[side] = loop;
      view.chooseLoop(side, loop);
      if (keys.pairs.length || keys.pending) {
        keys.clear();
        app.setStatus(`${side}: loop ${loop} chosen — the key pairs of the other loop were cleared`);
      }
      changed();
    }

    function lookAt(side) {
      const loop = chosenLoop(side);
      if (!loop) return;
      const m = meshes[side];
      // The outward direction of the opening: minus the loop's area vector (merge-geometry.js).
      let area = new THREE.Vector3();
      const c = new THREE.Vector3();
      const p = (v) => new THREE.Vector3(m.welded[3 * v], m.welded[3 * v + 1], m.welded[3 * v + 2]);
      for (const v of loop) c.add(p(v));
      c.divideScalar(loop.length);
      loop.forEach((v, i) => { area.add(p(v).sub(c).cross(p(loop[(i + 1) % loop.length]).sub(c))); });
      area = area.negate().normalize();
      view.lookAtLoop(side, area);
    }

    // ---- pointer: key picks (snap to the boundary), cut placement, the brush

    const brush = new Brush(view.brushTarget('source'));
    const brushActive = () => visible && brushOn && merge.mode === 'dependent' && Boolean(meshes.source) && !view.showingResult;

    attachPointerPicking({ renderer: viewer.renderer, pickAt: (x, y) => (visible ? { x, y } : null) }, {
      onHover(at) {
        if (!visible || brushActive()) return;
        if (!at || merge.tool || view.showingResult) {
          view.showHover(null);
          $('mg-hover').textContent = merge.tool && at ? (merge.tool === 'plane' ? 'click: put the cut plane here' : 'click: the centre of the disk') : '';
          return;
        }
        const pick = view.nearestBoundaryVertex(at.x, at.y);
        view.showHover(pick);
        $('mg-hover').textContent = pick ? `${pick.side} loop ${pick.loop}, vertex #${pick.welded}` : '';
      },
      onClick(at) {
        if (!visible || !at || brushActive() || view.gizmoBusy() || state.busy) return;
        if (merge.tool) {
          cutClick(at);
          return;
        }
        if (!inputsReady() || view.showingResult) return;
        const pick = view.nearestBoundaryVertex(at.x, at.y);
        if (!pick) {
          $('mg-hover').textContent = 'no boundary vertex near the click: click on or next to a yellow / blue loop';
          return;
        }
        if (merge.loops[pick.side] !== pick.loop) setLoop(pick.side, pick.loop);
        keys.click(pick.side, pick.welded);
        merge.selected = -1;
        changed();
      },
    });

    // The brush paints fixed handles on the source (dependent mode).
    const canvas = viewer.renderer.domElement;
    let painting = false;
    let lastPainted = null;
    function paintAt(x, y, erase) {
      const raw = brush.verticesAlong(lastPainted ?? { x, y }, { x, y });
      lastPainted = { x, y };
      const toWelded = view.sides.source.toWelded;
      let any = false;
      for (const r of raw) {
        const w = toWelded[r];
        if (fixedSet[w] !== (erase ? 0 : 1)) {
          fixedSet[w] = erase ? 0 : 1;
          any = true;
        }
      }
      if (any) {
        showColors('source');
        changed();
      }
    }
    canvas.addEventListener('pointerdown', (e) => {
      if (!brushActive() || e.button !== 0) return;
      painting = true;
      canvas.setPointerCapture(e.pointerId);
      lastPainted = null;
      paintAt(e.clientX, e.clientY, e.shiftKey);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!brushActive()) return;
      brush.showCursor(e.clientX, e.clientY, { erase: e.shiftKey });
      if (painting) paintAt(e.clientX, e.clientY, e.shiftKey);
    });
    const stopPainting = () => { painting = false; };
    canvas.addEventListener('pointerup', stopPainting);
    canvas.addEventListener('pointercancel', stopPainting);
    canvas.addEventListener('pointerleave', () => brush.showCursor(null));
    function setBrush(on) {
      brushOn = on;
      viewer.controls.enabled = !brushActive();
      if (!brushActive()) brush.showCursor(null);
      refresh();
    }
    $('mg-brush').addEventListener('click', () => setBrush(!brushOn));
    $('mg-brush-radius').addEventListener('input', () => brush.setRadius(Number($('mg-brush-radius').value)));
    brush.setRadius(Number($('mg-brush-radius').value));
    $('mg-fixed-clear').addEventListener('click', () => {
      fixedSet?.fill(0);
      showColors('source');
      changed();
    });

    // ---- cut tools

    const tool = () => root.querySelector('input[name="mg-tool"]:checked').value || null;
    const diskRadius = (side) => (Number($('mg-disk-radius').value) / 100) * bboxDiagonal(meshes[side].welded);

    function refreshCut() {
      merge.tool = tool();
      $('mg-plane-controls').hidden = merge.tool !== 'plane';
      $('mg-disk-controls').hidden = merge.tool !== 'disk';
      const at = plane?.side ?? disk?.side ?? null;
      let hint = '';
      if (merge.tool === 'plane') {
        hint = plane
          ? `Plane on the ${plane.side}: red is removed (keeps the arrow's side and, of that, the piece the plane was clicked on). Move or turn it with the gizmo; Flip side; then Cut.`
          : 'Click on a mesh where the plane goes.';
      } else if (merge.tool === 'disk') {
        hint = disk ? `Disk on the ${disk.side} around vertex #${disk.welded}: red is removed. Set the radius, then Cut.` : 'Click the vertex at the centre of the hole.';
      }
      $('mg-cut-hint').textContent = hint;
      if (merge.tool === 'disk' && (disk || meshes.target)) {
        const side = disk?.side ?? 'target';
        if (meshes[side]) $('mg-disk-radius-value').textContent = `${$('mg-disk-radius').value}% of the diagonal = ${fixed(diskRadius(side))}`;
      }
      $('mg-cut-apply').disabled = !(plane || disk) || Boolean(state.busy);
      const undoSide = at ?? (meshes.source?.cuts.length ? 'source' : meshes.target?.cuts.length ? 'target' : null);
      $('mg-cut-undo').disabled = !undoSide || !meshes[undoSide]?.cuts.length || Boolean(state.busy);
    }

    function setPlane(next) {
      const was = plane?.side;
      plane = next;
      if (next) {
        view.showPlane(next.side, next);
        view.attachGizmo('plane', root.querySelector('input[name="mg-plane-mode"]:checked').value);
      } else {
        view.showPlane(null);
        if (merge.mode === 'dependent' && visible) attachPlacementGizmo();
      }
      if (was) showColors(was);
      if (next) showColors(next.side);
    }
    view.onPlane = ({ point, normal }) => {
      if (!plane) return;
      plane.point = point;
      plane.normal = normal;
      showColors(plane.side);
      refreshCut();
    };

    function cutClick(at) {
      const hit = view.pickSurface(at.x, at.y);
      if (!hit) {
        $('mg-hover').textContent = 'the click missed the meshes';
        return;
      }
      if (merge.tool === 'plane') {
        const normal = root.querySelector('input[name="mg-normal"]:checked').value === 'view'
          ? view.viewDirectionLocal(hit.side).negate()
          : hit.normalLocal.clone();
        if (disk) { const s = disk.side; disk = null; view.showDiskCentre(null); showColors(s); }
        setPlane({ side: hit.side, point: hit.local, normal });
      } else {
        if (plane) setPlane(null);
        const was = disk?.side;
        disk = { side: hit.side, welded: hit.welded };
        view.showDiskCentre(hit.side, hit.welded);
        if (was && was !== hit.side) showColors(was);
        showColors(hit.side);
      }
      refreshCut();
    }

    for (const radio of root.querySelectorAll('input[name="mg-tool"]')) {
      radio.addEventListener('change', () => {
        merge.tool = tool();
        if (merge.tool !== 'plane' && plane) setPlane(null);
        if (merge.tool !== 'disk' && disk) {
          const s = disk.side;
          disk = null;
          view.showDiskCentre(null);
          showColors(s);
        }
        if (merge.tool) setBrush(false);
        refresh();
      });
    }
    for (const radio of root.querySelectorAll('input[name="mg-plane-mode"]')) {
      radio.addEventListener('change', () => { if (plane) view.setGizmoMode(radio.value); });
    }
    $('mg-flip').addEventListener('click', () => {
      if (!plane) return;
      plane.normal = plane.normal.clone().negate();
      view.showPlane(plane.side, plane);
      showColors(plane.side);
    });
    $('mg-disk-radius').addEventListener('input', () => {
      if (disk) showColors(disk.side);
      refreshCut();
    });
    $('mg-cut').addEventListener('toggle', () => {
      if (!$('mg-cut').open && tool()) {
        root.querySelector('input[name="mg-tool"][value=""]').checked = true;
        root.querySelector('input[name="mg-tool"][value=""]').dispatchEvent(new Event('change'));
      }
    });

    $('mg-cut-apply').addEventListener('click', async () => {
      let side;
      let cut;
      if (plane) {
        side = plane.side;
        const n = plane.normal.clone().normalize();
        const p = plane.point;
        // Keep the arrow's side, and of it the piece next to where the plane was put.
        const reach = 0.02 * bboxDiagonal(meshes[side].welded);
        cut = { plane: [p.x, p.y, p.z, n.x, n.y, n.z], keep: [p.x + reach * n.x, p.y + reach * n.y, p.z + reach * n.z] };
      } else if (disk) {
        side = disk.side;
        cut = { disk: [disk.welded, diskRadius(side)] };
      } else {
        return;
      }
      const m = meshes[side];
      const ok = await openSide(side, m.files, [...m.cuts, cut], { label: `Cutting the ${side}` });
      if (ok) {
        setPlane(null);
        disk = null;
        view.showDiskCentre(null);
        showColors(side);
        refresh();
      }
    });
    $('mg-cut-undo').addEventListener('click', async () => {
      const side = plane?.side ?? disk?.side ?? (meshes.source?.cuts.length ? 'source' : 'target');
      const m = meshes[side];
      if (!m?.cuts.length) return;
      await openSide(side, m.files, m.cuts.slice(0, -1), { label: `Undoing the last cut of the ${side}` });
    });

    // ---- mode, placement

    function attachPlacementGizmo() {
      if (plane || !meshes.source || view.showingResult) return;
      view.attachGizmo('place', root.querySelector('input[name="mg-place-mode"]:checked').value);
    }

    function placeSource() {
      const t = chosenLoop('target');
      const s = chosenLoop('source');
      if (!t || !s) return false;
      const first = keys.pairs[0] ?? null;
      merge.placement = placeOnLoop(meshes.target.welded, t, meshes.source.welded, s, first);
      view.setPlacement(merge.placement);
      return true;
    }
    view.onPlacement = (elements) => {
      merge.placement = elements;
      if (result) clearResult();
      refresh();
    };

    function setMode(mode) {
      merge.mode = mode;
      root.querySelector(`input[name="mg-mode"][value="${mode}"]`).checked = true;
      if (mode === 'dependent') {
        // A first visit: start from the source put onto the target's loop.
        if (merge.placement.every((v, i) => v === identity[i])) placeSource();
        attachPlacementGizmo();
      } else {
        if (view.gizmoKind === 'place') view.detachGizmo();
        setBrush(false);
      }
      showColors('source');
      if (result) clearResult();
      arrange({ frame: true });
      refresh();
    }
    for (const radio of root.querySelectorAll('input[name="mg-mode"]')) radio.addEventListener('change', () => setMode(radio.value));
    for (const radio of root.querySelectorAll('input[name="mg-place-mode"]')) {
      radio.addEventListener('change', () => { if (view.gizmoKind === 'place') view.setGizmoMode(radio.value); });
    }
    $('mg-place').addEventListener('click', () => {
      if (!placeSource()) app.showError({ code: 'InvalidArgument', message: 'choose the boundary loop of both meshes first (step 3)' });
      if (result) clearResult();
      arrange({ frame: true });
      refresh();
    });
    $('mg-place-reset').addEventListener('click', () => {
      merge.placement = identity;
      view.setPlacement(identity);
      if (result) clearResult();
      arrange({ frame: true });
      refresh();
    });

    // ---- the spec

    function specComment() {
      const parts = sideNames.map((s) => {
        const m = meshes[s];
        if (!m.cuts.length) return `${s} ${m.info.name}`;
        let file = m.info.name;
        const steps = m.cuts.map((c, i) => {
          const out = `${stem(m.info.name)}-cut${i + 1}.off`;
          const command = `meshmorph cut ${file} ${cutCommand(c)} --out ${out}`;
          file = out;
          return command;
        });
        return `${s} ${file} = ${steps.join(' && ')}`;
      });
      const moved = merge.mode === 'dependent' && merge.placement.some((v, i) => v !== identity[i]);
      return `MeshMorph page: ${parts.join('; ')}${moved ? '; source placed in the page: use the source it saved (Save source)' : ''}`;
    }

    function currentSpec() {
      const options = { ...(form ? form.values() : {}) };
      if (merge.mode === 'dependent') options.mode = 'dependent';
      const fixedList = merge.mode === 'dependent' && fixedSet ? [...fixedSet.keys()].filter((v) => fixedSet[v]) : [];
      return buildMergeSpec({ pairs: keys.pairs, fixed: fixedList, options, comment: specComment() });
    }

    function checkReady() {
      if (!inputsReady()) throw new MeshMorphError('InvalidArgument', 'load the target and the source first (steps 1 and 2)');
      const problem = keyPairsProblem(keys.pairs, chosenLoop('target'), chosenLoop('source'));
      if (problem) throw new MeshMorphError('InvalidArgument', `the key pairs are not ready: ${problem}`);
    }

    // ---- merge

    function clearResult() {
      result = null;
      merge.result = null;
      merge.check = null;
      $('mg-check-out').textContent = '';
      view.clearResult();
      if (merge.mode === 'dependent' && visible && view.gizmoKind !== 'place') attachPlacementGizmo();
    }

    async function runMerge(placement) {
      const spec = currentSpec();
      const options = { targetSlot: slots.target, sourceSlot: slots.source, spec };
      if (placement) options.placement = placement;
      const started = performance.now();
      const ran = await app.runOp('Merging', 'merge', options);
      if (!ran) return null;
      return { ...ran, spec, wallMs: performance.now() - started };
    }

    $('mg-run').addEventListener('click', async () => {
      try {
        checkReady();
      } catch (e) {
        app.showError(e);
        return;
      }
      const ran = await runMerge(merge.mode === 'dependent' ? merge.placement : null);
      if (!ran) return;
      const { buffers: b, info } = ran;
      result = { positions: b.positions, indices: b.indices };
      merge.runs += 1;
      merge.result = { ...info, wallMs: ran.wallMs, spec: ran.spec };
      merge.showing = 'result';
      root.querySelector('input[name="mg-show"][value="result"]').checked = true;
      const zipFaces = info.seams.reduce((n, s) => n + s.zipFaces, 0);
      view.setResult({ positions: Float32Array.from(b.positions), indices: b.indices, zipFaces, sourceOffset: info.sourceOffset });
      view.showSeam($('mg-seam').checked);
      view.showResult(true);
      view.frameCamera();
      setBrush(false);
      showReport();
      refresh();
      app.setStatus(`merged in ${fixed(info.milliseconds / 1000)} s: ${info.vertices} vertices, ${info.boundaryLoops} boundary loop(s)`);
    });

    function showReport() {
      const info = merge.result;
      const rows = [
        ['merged mesh', `${info.vertices} vertices, ${info.faces} faces, ${info.boundaryLoops} boundary loop${info.boundaryLoops === 1 ? '' : 's'}${info.boundaryLoops === 0 ? ' (watertight)' : ''}`],
      ];
      info.seams.forEach((s, i) => {
        const label = info.seams.length > 1 ? `seam ${i + 1}` : 'seam';
        rows.push([label, `${s.zipFaces} zip faces (${s.removedFaces} target band faces removed), smallest angle ${fixed(s.minAngleDeg)}°, ${s.flippedFaces} flipped`]);
        rows.push(['dihedral angles', `max ${fixed(s.dihedralMaxDeg)}°, mean ${fixed(s.dihedralMeanDeg)}° across the seam edges`]);
      });
      const { stats } = info;
      rows.push(['solve', `${stats.boundaryConstraints} boundary constraints${stats.refinedVertices ? `, ${stats.refinedVertices} source loop vertices added (Sec. 6 refinement)` : ''}${stats.degenerateVertices ? `, ${stats.degenerateVertices} degenerate vertices` : ''}`]);
      rows.push(['time', `${fixed(info.milliseconds / 1000)} s in the worker (precompute ${fixed(stats.ms.precompute, 3)} ms, solve ${fixed(stats.ms.solve, 3)} ms, zip ${fixed(stats.ms.zip, 3)} ms)`]);
      const list = $('mg-report');
      list.replaceChildren();
      for (const [term, text] of rows) {
        list.append(Object.assign(document.createElement('dt'), { textContent: term }), Object.assign(document.createElement('dd'), { textContent: text }));
      }
    }

    for (const radio of root.querySelectorAll('input[name="mg-show"]')) {
      radio.addEventListener('change', () => {
        merge.showing = radio.value;
        view.showResult(radio.value === 'result');
        if (radio.value === 'inputs' && merge.mode === 'dependent') attachPlacementGizmo();
        view.frameCamera();
      });
    }
    $('mg-seam').addEventListener('change', () => view.showSeam($('mg-seam').checked));

    // Fig. 1: the same merge with the source moved by a random similarity.
    $('mg-check').addEventListener('click', async () => {
      if (!result || merge.mode !== 'independent') return;
      const reach = bboxDiagonal(meshes.target.welded);
      const placement = randomSimilarity(reach);
      const ran = await runMerge(placement);
      if (!ran) return;
      const a = result.positions;
      const b = ran.buffers.positions;
      let text;
      if (a.length !== b.length) {
        text = `different meshes: ${a.length / 3} and ${b.length / 3} vertices`;
        merge.check = { same: false, vertices: [a.length / 3, b.length / 3] };
      } else {
        let max = 0;
        for (let i = 0; i < a.length; i += 3) max = Math.max(max, Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]));
        const relative = max / bboxDiagonal(a);
        merge.check = { same: true, maxDifference: relative, placement };
        text = `Moved the source (scale ${fixed(Math.cbrt(Math.abs(new THREE.Matrix4().fromArray(placement).determinant())))}, turned, shifted) and merged again: the vertices differ by at most ${relative.toExponential(1)} of the diagonal — the same mesh.`;
      }
      $('mg-check-out').textContent = text;
    });

    // ---- files

    $('mg-save').addEventListener('click', () => {
      if (keys.pairs.length < minKeys || !inputsReady()) return;
      const spec = currentSpec();
      merge.saved = spec;
      download(new TextEncoder().encode(`${JSON.stringify(spec, null, 1)}\n`), `${stem(meshes.target.info.name)}-${stem(meshes.source.info.name)}.merge.json`, 'application/json');
    });

    $('mg-load').addEventListener('change', async () => {
      const file = $('mg-load').files[0];
      $('mg-load').value = '';
      if (!file) return;
      try {
        if (!inputsReady()) throw new MeshMorphError('InvalidArgument', 'load the target and the source before their merge spec');
        let json;
        try {
          json = JSON.parse(await file.text());
        } catch (e) {
          throw new MeshMorphError('ParseError', `${file.name}: ${e.message}`);
        }
        const spec = readMergeSpec(json, { targetVertices: meshes.target.info.weldedVertices, sourceVertices: meshes.source.info.weldedVertices });
        const { mode = 'independent', ...options } = spec.options;
        if (!['independent', 'dependent'].includes(mode)) throw new MeshMorphError('ParseError', `merge spec: options.mode must be "independent" or "dependent", not ${JSON.stringify(mode)}`);
        // Loops: as the spec names them, else the loop of the first key.
        for (const [side, explicit, key] of [['target', spec.targetLoop, spec.pairs[0]?.[0]], ['source', spec.sourceLoop, spec.pairs[0]?.[1]]]) {
          const loops = meshes[side].info.loops;
          const loop = explicit >= 0 ? explicit : loops.findIndex((l) => l.includes(key));
          if (loop < 0 || loop >= loops.length) throw new MeshMorphError('InvalidArgument', `merge spec: the ${side} key ${key} is not on a boundary loop of ${meshes[side].info.name}`);
          merge.loops[side] = loop;
          view.chooseLoop(side, loop);
        }
        keys.clear();
        keys.pairs.push(...spec.pairs);
        fixedSet.fill(0);
        for (const v of spec.fixed) fixedSet[v] = 1;
        form?.setValues(options);
        merge.selected = -1;
        if (mode !== merge.mode) setMode(mode);
        showColors('source');
        changed();
      } catch (e) {
        app.showError(e);
      }
    });

    $('mg-export').addEventListener('click', async () => {
      if (!result) return;
      const exported = await app.runOp('Exporting GLB', 'mergeExport', { slot: slots.target, format: 'glb' },
        { positions: result.positions.slice(), indices: result.indices.slice() });
      if (!exported) return;
      download(exported.buffers.bytes, `${stem(meshes.target.info.name)}-merged.glb`, 'model/gltf-binary');
      merge.exports += 1;
    });

    for (const side of sideNames) {
      $(`mg-save-${side}`).addEventListener('click', async () => {
        if (!meshes[side]) return;
        const options = { slot: slots[side], format: 'off' };
        if (side === 'source' && merge.mode === 'dependent') options.placement = merge.placement;
        const saved = await app.runOp(`Saving the ${side}`, 'mergeExport', options);
        if (!saved) return;
        const suffix = meshes[side].cuts.length ? '-cut' : '';
        const placed = options.placement && options.placement.some((v, i) => v !== identity[i]) ? '-placed' : '';
        download(saved.buffers.bytes, `${stem(meshes[side].info.name)}${suffix}${placed}.off`, 'text/plain');
      });
    }

    // ---- wiring

    app.on('ready', async () => {
      try {
        const schema = (await client.run('optionSchema', { job: 'merge' }).promise).info;
        // Widths (× a diagonal) on sliders over the range that matters; a spec's larger value widens it.
        form = new OptionsForm(schema.options.filter((o) => o.name !== 'mode'), {
          title: 'Options', sliders: { roi_width: 1, transition_target_width: 0.5, transition_source_width: 0.5 },
        });
        $('mg-options').append(form.element);
      } catch (e) {
        app.showError(e);
      }
      refresh();
    });
    app.on('job', (job) => {
      const was = visible;
      visible = job === 'merge';
      if (visible === was) return;
      view.setActive(visible);
      if (!visible) {
        view.showHover(null);
        setBrush(false);
      } else if (merge.mode === 'dependent') {
        attachPlacementGizmo();
      }
    });

    app.hooks.mergeVertexOnScreen = (side, welded) => view.vertexOnScreen(side, welded);
    app.hooks.mergeResult = () => (result ? { positions: Array.from(result.positions), indices: Array.from(result.indices) } : null);
    app.hooks.mergePlane = () => (plane ? { side: plane.side, point: plane.point.toArray(), normal: plane.normal.toArray() } : null);
    app.hooks.mergeCentreOnScreen = (side) => view.centreOnScreen(side);
    app.hooks.mergeLoops = () => ({ target: meshes.target?.info.loops ?? [], source: meshes.source?.info.loops ?? [] });
    app.hooks.mergeProblem = (pairs) => keyPairsProblem(pairs, chosenLoop('target'), chosenLoop('source'));
    // The source vertex furthest from its chosen loop's centre (a place for a fixed handle).
    app.hooks.mergeFarthestSourceVertex = () => {
      const p = meshes.source.welded;
      const c = [0, 0, 0];
      const loop = chosenLoop('source');
      for (const v of loop) for (let k = 0; k < 3; ++k) c[k] += p[3 * v + k] / loop.length;
      let best = 0;
      let far = -1;
      for (let v = 0; v < p.length / 3; ++v) {
        const d = Math.hypot(p[3 * v] - c[0], p[3 * v + 1] - c[1], p[3 * v + 2] - c[2]);
        if (d > far) { far = d; best = v; }
      }
      return best;
    };
    // Dependent mode: how far the fixed source vertices are from where the placement put them.
    app.hooks.mergeFixedError = () => {
      if (!result || !merge.result) return null;
      const m = merge.result.spec.options?.mode === 'dependent' ? merge.placement : identity;
      const p = meshes.source.welded;
      let max = 0;
      for (const v of merge.result.spec.fixed ?? []) {
        const q = [0, 1, 2].map((i) => m[i] * p[3 * v] + m[4 + i] * p[3 * v + 1] + m[8 + i] * p[3 * v + 2] + m[12 + i]);
        const o = 3 * (merge.result.sourceOffset + v);
        max = Math.max(max, Math.hypot(q[0] - result.positions[o], q[1] - result.positions[o + 1], q[2] - result.positions[o + 2]));
      }
      return max;
    };
    refresh();
    return root;
  },
};
