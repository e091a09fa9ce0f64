// The Transfer job: give a source mesh the pose of a reference mesh (spectral pose transfer,
// docs/transfer.md; worker ops `transfer` and `compare` in worker/ops/transfer.js). A guided
// step list leads through
//   1 load the reference (pose) mesh   2 load the source (shape) mesh
//   3 landmark pairs — needed when the connectivity differs (same vertex count and faces: the
//     core generates 30 pairs itself): click a vertex on the reference, then its match on the
//     source; pairs are numbered and colour-matched on both meshes and listed in a table
//     (select, delete; a click with a pair selected moves its end); save / load as the CLI's landmark JSON (welded indices)
//   4 run (method yin / kovnatsky / levy, options from optionSchema {job: 'transfer'})
//   5 compare (Γ dominance, Γ heat map, flipped faces and detail change from `compare`, result
//     against source) and export the result as GLB (the source's asset with the new positions).
// Parts (paper 000 Sec. 4.3, worker op `partTransfer`): with Parts = automatic or a loaded part
// file (the CLI's --parts JSON) the run is the hierarchical transfer — the whole-body result
// (shown as Level 1), then each part pair transferred again and glued back; the result lists
// every part (kept, rejected by the quality gate, or skipped, with the core's reason), colours
// the parts on the source side, and Save parts writes the pairs used (the proposals, to edit).
// Both meshes are shown side by side (view/pair-view.js) while the job is shown; the Mesh and
// Edit jobs keep their own mesh. The meshes live in their own worker slots (slots below).
// State it owns (window.__meshmorph.state.transfer): {step, reference, source ({name,
// rawVertices, weldedVertices} or null), sameConnectivity, pairs, pending, selected, method,
// result ({info, metrics, toReference, options, parts?: {info (partTransfer's)}}) or
// null, showing ('source' | 'level1' | 'result'), runs, saved (the last saved landmark file),
// exports, parts ('none' | 'auto' | 'file'), partsFile ({name, text, count}) or null}. Test hooks (window.__meshmorph.hooks):
// transferVertexOnScreen(side, rawVertex) → {x, y, visible}, transferResult() → welded
// positions or null, transferLevel1() → the level-1 welded positions of a parts run or null,
// transferShown(side = 'source') → a side's displayed (raw) positions, transferColors() → the
// source side's vertex colours (raw, 3 a vertex) or null.
import { unweldValues } from '../../lib/arrays.js';
import { LandmarkPairs, landmarkFile, minLandmarks, readLandmarkFile } from '../../lib/landmarks.js';
import { samples } from '../../lib/samples.js';
import { weldedTriangles } from '../../lib/vertex-sets.js';
import { documentMaterials, disposeDocumentMaterials, isGltfName } from '../../view/document-materials.js';
import { LandmarkMarkers, labelTolerance, pairColor } from '../../view/landmark-markers.js';
import { VertexMarker } from '../../view/marker.js';
import { PairView } from '../../view/pair-view.js';
import { attachPointerPicking } from '../../view/pointer-picking.js';
import { vertexOnScreen } from '../../view/screen-space.js';
import { download } from '../download.js';
import { finder, fromHtml } from '../dom.js';
import { sampleFiles, userFiles } from '../files.js';
import { GammaMap } from '../gamma-map.js';
import { LandmarkTable } from '../landmark-table.js';
import { OptionsForm } from '../options-form.js';
import { StepList } from '../step-list.js';

const slots = { reference: 'transfer-reference', source: 'transfer-source' };
const example = { reference: 'cat-07', source: 'cat' }; // same connectivity (docs/transfer.md)
const fileTypes = '.glb,.gltf,.bin,.obj,.off,.ply,.png,.jpg,.jpeg,.webp';

const markup = `
<section class="transfer">
  <h2>Pose transfer</h2>
  <div id="tr-steps"></div>
  <div class="row side-row">
    <label for="tr-reference-sample" title="The mesh whose pose is copied (left)">Reference</label>
    <select id="tr-reference-sample" data-idle></select>
    <label class="button file" title="Open a reference mesh file">Open…<input type="file" id="tr-reference-file" multiple accept="${fileTypes}" data-idle /></label>
  </div>
  <div class="row side-row">
    <label for="tr-source-sample" title="The mesh that takes the pose and keeps its details (right)">Source</label>
    <select id="tr-source-sample" data-idle></select>
    <label class="button file" title="Open a source mesh file">Open…<input type="file" id="tr-source-file" multiple accept="${fileTypes}" data-idle /></label>
  </div>
  <div class="row">
    <button id="tr-example" type="button" data-idle title="Cat, pose 07 as the reference and the cat's rest pose as the source (same connectivity)">Load the cat example</button>
  </div>
  <p id="tr-meshes" class="hint"></p>
  <div class="row" role="radiogroup" aria-label="View">
    <span class="hint">View</span>
    <label title="Both meshes in one view, one camera"><input type="radio" name="tr-view" value="side" checked /> Side by side</label>
    <label title="Two views, each with its own camera"><input type="radio" name="tr-view" value="split" /> Split</label>
    <label title="Both meshes at the same place, see-through"><input type="radio" name="tr-view" value="overlay" /> Overlay</label>
  </div>
  <div class="row">
    <label title="glTF meshes: their own materials and textures (not in Overlay); off: the plain colours"><input type="checkbox" id="tr-materials" checked /> Materials</label>
  </div>
  <div class="row" id="tr-link-row" hidden>
    <label title="Orbiting one view moves the other the same way"><input type="checkbox" id="tr-link" checked /> Link the cameras</label>
  </div>
  <h3>Landmarks</h3>
  <p id="tr-landmark-hint" class="hint"></p>
  <p id="tr-hover" class="pick-hover"></p>
  <div class="row">
    <button id="tr-suggest" type="button" data-idle title="Pairs at the extremities (tips of limbs, head, tail) found on both meshes; accept or reject each">Suggest pairs</button>
  </div>
  <div id="tr-suggestions" hidden>
    <table class="landmarks suggestions"><thead><tr><th>#</th><th>reference</th><th>source</th><th></th></tr></thead><tbody></tbody></table>
    <div class="row">
      <button id="tr-suggest-accept-all" type="button">Accept all</button>
      <button id="tr-suggest-reject-all" type="button">Reject all</button>
    </div>
  </div>
  <div id="tr-table"></div>
  <div class="row">
    <button id="tr-landmarks-clear" type="button" title="Delete every pair">Clear</button>
    <button id="tr-landmarks-save" type="button" title="The pairs as the CLI's landmark JSON (meshmorph transfer --landmarks)">Save JSON</button>
    <label class="button file" title="Open a landmark JSON {&quot;pairs&quot;: [[reference, source], ...]}">Load JSON…
      <input type="file" id="tr-landmarks-load" accept=".json,application/json" data-idle />
    </label>
  </div>
  <h3>Run</h3>
  <div class="row">
    <label for="tr-method">Method</label> <select id="tr-method" data-idle>
      <option value="yin" title="the paper: the source's cage follows the reference's low frequencies">yin (cage, paper 000)</option>
      <option value="kovnatsky" title="coefficient swap in coupled bases (Kovnatsky 2013)">kovnatsky (baseline)</option>
      <option value="levy" title="coefficient swap in plain eigenbases (Lévy 2006)">levy (baseline)</option>
    </select>
    <button id="tr-run" type="button" data-idle>Run transfer</button>
  </div>
  <div class="row">
    <label for="tr-parts" title="Paper 000 Sec. 4.3: after the whole-body transfer, corresponding parts (limbs, head, tail) are transferred again as pairs of their own and glued back">Parts</label>
    <select id="tr-parts" data-idle>
      <option value="none" title="the whole-body transfer only">none (one level)</option>
      <option value="auto" title="parts proposed where the result's pose disagrees most with the reference, cut at narrow necks">automatic</option>
      <option value="file" disabled title="the part pairs of a loaded part file">from file</option>
    </select>
    <label class="button file" title="A part file: the CLI's --parts JSON (plane cuts or geodesic disks around a seed vertex, nested levels)">Load parts…<input type="file" id="tr-parts-load" accept=".json,application/json" data-idle /></label>
    <button id="tr-parts-save" type="button" title="The part pairs of the last run (with automatic parts: the proposals, to edit and load again) as the CLI's --parts JSON" disabled>Save parts</button>
  </div>
  <p id="tr-parts-hint" class="hint"></p>
  <div id="tr-options"></div>
  <div id="tr-part-options"></div>
  <div id="tr-result" hidden>
    <h3>Result</h3>
    <div class="row" role="radiogroup" aria-label="Show">
      <label><input type="radio" name="tr-show" value="source" /> Source</label>
      <label id="tr-show-level1" title="The whole-body transfer before the parts were glued back"><input type="radio" name="tr-show" value="level1" /> Level 1</label>
      <label><input type="radio" name="tr-show" value="result" checked /> Result</label>
      <button id="tr-export" type="button" data-idle>Export GLB</button>
    </div>
    <div class="gamma-row">
      <div id="tr-gamma"></div>
      <dl id="tr-metrics" class="metrics"></dl>
    </div>
    <div id="tr-parts-result" hidden>
      <div class="row"><label title="Each part's region in its own colour on the source side"><input type="checkbox" id="tr-part-colours" checked /> Colour the parts</label></div>
      <p id="tr-parts-proposals" class="hint" hidden></p>
      <table class="landmarks parts"><thead><tr><th>#</th><th>part</th><th title="part level; r2, r3: proposed in the second or third round">level</th><th>result</th><th>vertices</th><th title="registration by the local frames (Sec. 4.3), or by the part's landmarks when kept rigid">rotation</th></tr></thead><tbody></tbody></table>
    </div>
  </div>
</section>`;

// First raw vertex of every welded vertex (markers are placed on displayed vertices).
function weldedToRaw(toWelded, count) {
  const out = new Int32Array(count).fill(-1);
  for (let r = toWelded.length - 1; r >= 0; --r) out[toWelded[r]] = r;
  return out;
}

// Raw-layout vertex colours of part regions: labels per welded vertex (-1 outside every part).
function partRegionColors(labels, toWelded) {
  const colors = new Float32Array(3 * toWelded.length);
  for (let r = 0; r < toWelded.length; ++r) {
    const label = labels[toWelded[r]];
    const c = label < 0 ? [0.85, 0.8, 0.75] : pairColor(label);
    colors.set(c, 3 * r);
  }
  return colors;
}

// Parts a partTransfer run kept (the others were skipped or rejected by the quality gate).
const keptParts = (parts) => parts.filter((p) => p.ok && !p.rejected);

const sameArrays = (a, b) => a.length === b.length && a.every((v, i) => v === b[i]);
const fixed = (v, digits = 3) => (Number.isFinite(v) ? Number(v.toPrecision(digits)).toString() : '–');

export const panel = {
  id: 'transfer',
  title: 'Transfer',
  create(app) {
    const { state, viewer, client } = app;
    const root = fromHtml(markup);
    const $ = finder(root);
    const transfer = {
      step: 0, reference: null, source: null, sameConnectivity: false, pairs: [], pending: null, selected: -1,
      method: 'yin', result: null, showing: 'result', runs: 0, saved: null, exports: 0,
      view: 'side', linked: true, suggestions: [], loading: null, parts: 'none', partsFile: null,
    };
    state.transfer = transfer;

    const steps = new StepList([
      { title: 'Load the reference (pose) mesh' },
      { title: 'Load the source (shape) mesh' },
      { title: 'Landmark pairs' },
      { title: 'Run the transfer' },
      { title: 'Compare / export' },
    ]);
    $('tr-steps').append(steps.element);

    const pair = new PairView(viewer);
    const landmarks = new LandmarkPairs();
    const markers = new LandmarkMarkers(pair, () => viewer.requestRender());
    const hoverMarker = new VertexMarker({ color: 0xffd23f, onChange: () => viewer.requestRender() });
    const table = new LandmarkTable({
      onSelect(i) { transfer.selected = i; refresh(); },
      onDelete(i) {
        landmarks.remove(i);
        transfer.selected = -1;
        refresh();
      },
    });
    $('tr-table').append(table.element);
    const gammaMap = new GammaMap();
    $('tr-gamma').append(gammaMap.element);

    // Per side: {info (load result info), toWelded, weldedToRaw, restRaw (displayed positions),
    // triangles (welded)}.
    const meshes = { reference: null, source: null };
    let result = null;       // welded result positions (Float32Array #W·3) of the last run
    let resultRaw = null;    // the same in the source's raw layout
    let level1 = null;       // a parts run's level-1 result (welded)
    let level1Raw = null;    // the same, raw layout
    let partColors = null;   // a parts run's region colours, raw layout (3 a vertex)
    let form = null;
    let partForm = null;
    let visible = false;

    // ---- showing the state

    const landmarksReady = () => (transfer.sameConnectivity && landmarks.pairs.length === 0) || landmarks.pairs.length >= minLandmarks;

    function refresh() {
      transfer.pairs = landmarks.pairs.map((p) => [...p]);
      transfer.pending = landmarks.pending ? { ...landmarks.pending } : null;
      if (transfer.selected >= landmarks.pairs.length) transfer.selected = -1;
      const both = Boolean(meshes.reference && meshes.source);
      const n = landmarks.pairs.length;
      let hint;
      if (!both) hint = 'Load both meshes first.';
      else if (transfer.sameConnectivity && n === 0) hint = 'Same vertex count and faces: 30 landmark pairs are generated automatically. You may still click your own (at least 6).';
      else if (transfer.selected >= 0) hint = `Pair ${transfer.selected + 1} selected: a click on either mesh moves its end there. Click the row again to add new pairs.`;
      else hint = `${n} pair${n === 1 ? '' : 's'}${n < minLandmarks ? ` — at least ${minLandmarks} needed${transfer.sameConnectivity ? ' (or none: then they are generated)' : ''}` : ''}. Click a vertex on the reference (left), then its match on the source (right); select a pair in the table to move it.`;
      $('tr-landmark-hint').textContent = hint;

      if (!meshes.reference) {
        transfer.step = 0;
        steps.set(0, 'Pick a reference under Reference (or Load the cat example): the mesh whose pose is copied.');
      } else if (!meshes.source) {
        transfer.step = 1;
        steps.set(1, 'Pick a source under Source: the mesh that takes the pose and keeps its details.');
      } else if (!landmarksReady()) {
        transfer.step = 2;
        steps.set(2, transfer.sameConnectivity
          ? `Click ${minLandmarks - n} more pair(s), or Clear to use generated landmarks.`
          : `Different connectivity: click a vertex on the reference, then the matching one on the source (${n} of at least ${minLandmarks}); or Load JSON.`);
      } else if (!transfer.result) {
        transfer.step = 3;
        steps.set(3, `${transfer.sameConnectivity && n === 0 ? 'Landmarks are generated automatically (same connectivity). ' : `${n} landmark pairs. `}Choose the method and press Run transfer.`);
      } else {
        transfer.step = 4;
        steps.set(4, 'Toggle Source / Result, read Γ and the metrics, Export GLB.');
      }

      $('tr-meshes').textContent = both
        ? `${meshes.reference.info.name} (${meshes.reference.info.weldedVertices} v) → ${meshes.source.info.name} (${meshes.source.info.weldedVertices} v)${transfer.sameConnectivity ? ' · same connectivity' : ' · different connectivity'}`
        : '';
      $('tr-result').hidden = !transfer.result;
      showMarkers();
      table.show(landmarks.pairs, landmarks.pending, transfer.selected);
      $('tr-landmarks-save').disabled = n === 0;
      $('tr-landmarks-clear').disabled = n === 0 && !landmarks.pending;
    }

    // Landmarks are welded indices; markers go on the first displayed vertex of each.
    function showMarkers() {
      if (!meshes.reference || !meshes.source) {
        markers.clear();
        viewer.requestRender();
        return;
      }
      const raw = (side, w) => meshes[side].weldedToRaw[w];
      const pending = landmarks.pending ? { side: landmarks.pending.side, vertex: raw(landmarks.pending.side, landmarks.pending.vertex) } : null;
      markers.show(landmarks.pairs.map(([r, s]) => [raw('reference', r), raw('source', s)]), pending, transfer.selected);
    }

    function showSource() {
      if (!meshes.source) return;
      let shown = meshes.source.restRaw;
      if (transfer.showing === 'result' && resultRaw) shown = resultRaw;
      else if (transfer.showing === 'level1' && level1Raw) shown = level1Raw;
      pair.setPositions('source', shown.slice());
      pair.setColors('source', partColors && $('tr-part-colours').checked ? partColors : null);
      showMarkers();
    }

    // ---- loading

    // files: [{name, bytes}] with the mesh file first (ui/files.js).
    async function loadSide(side, files) {
      const [main] = files;
      const buffers = {};
      for (const f of files) buffers[f.name] = f.bytes;
      const copies = isGltfName(main.name) ? files.map((f) => ({ name: f.name, bytes: f.bytes.slice() })) : null;
      transfer.loading = side;
      const loaded = await app.runOp(`Loading ${main.name} (${side})`, 'load', { name: main.name, slot: slots[side] }, buffers, { restoreKey: `mesh:${slots[side]}` });
      transfer.loading = null;
      if (!loaded) return false;
      const { buffers: b, info } = loaded;
      meshes[side] = {
        info, toWelded: b.toWelded, weldedToRaw: weldedToRaw(b.toWelded, info.weldedVertices),
        restRaw: b.positions.slice(), triangles: weldedTriangles(b.indices, b.toWelded),
      };
      transfer[side] = { name: info.name, rawVertices: info.rawVertices, weldedVertices: info.weldedVertices };
      app.setStatus(`${side}: ${info.name}, ${info.weldedVertices} vertices, ${info.report.faces} faces · ${client.runtimeSummary}`);
      pair.setMesh(side, b, { open: info.report.boundaryLoopLengths.length > 0 || info.report.components === 0 });
      if (copies) {
        const entry = meshes[side];
        documentMaterials(copies, info.primitives, info.rawVertices).then((display) => {
          if (meshes[side] !== entry || display.error) return disposeDocumentMaterials(display);
          pair.setDocumentMaterials(side, display);
          return undefined;
        });
      }
      // A new mesh: pairs, suggestions and results of the old one mean nothing on it.
      landmarks.clear();
      setSuggestions([]);
      transfer.selected = -1;
      clearResult();
      const { reference, source } = meshes;
      transfer.sameConnectivity = Boolean(reference && source && reference.info.weldedVertices === source.info.weldedVertices
        && sameArrays(reference.triangles, source.triangles));
      refresh();
      return true;
    }

    async function loadSample(side, id) {
      const sample = samples.find((s) => s.id === id);
      if (!sample) return false;
      $(`tr-${side}-sample`).value = id;
      transfer.loading = side; // already while the files are fetched (drops wait for it)
      try {
        return await loadSide(side, await sampleFiles(sample));
      } catch (e) {
        app.showError(e);
        return false;
      } finally {
        transfer.loading = null;
      }
    }

    for (const side of ['reference', 'source']) {
      const select = $(`tr-${side}-sample`);
      select.add(new Option('— choose —', ''));
      for (const s of samples) select.add(new Option(s.label, s.id));
      select.add(new Option('(your file)', 'file'));
      select.addEventListener('change', () => {
        if (select.value && select.value !== 'file') loadSample(side, select.value);
      });
      const input = $(`tr-${side}-file`);
      input.addEventListener('change', async () => {
        const list = [...input.files]; // a copy: clearing the input empties its FileList
        input.value = '';
        if (!list.length) return;
        try {
          if (await loadSide(side, await userFiles(list))) select.value = 'file';
        } catch (e) {
          app.showError(e);
        }
      });
    }
    $('tr-example').addEventListener('click', async () => {
      if (await loadSample('reference', example.reference)) await loadSample('source', example.source);
    });

    // ---- landmark picking (both sides of the pair view)

    attachPointerPicking({ renderer: viewer.renderer, pickAt: (x, y) => (visible ? pair.pickAt(x, y) : null) }, {
      onHover(pick) {
        if (!visible) return;
        if (!pick) {
          hoverMarker.hide();
          $('tr-hover').textContent = '';
          return;
        }
        pair.sides[pick.side].mesh.add(hoverMarker.object);
        hoverMarker.setSize(pair.localRadius(pick.side) * 0.011);
        hoverMarker.show(pair.localPoint(pick.side, pick.vertex));
        $('tr-hover').textContent = `${pick.side} vertex #${pick.welded ?? pick.vertex}`;
      },
      onClick(pick) {
        if (!visible || !pick || !meshes.reference || !meshes.source) return;
        const vertex = pick.welded ?? pick.vertex;
        if (transfer.selected >= 0 && !landmarks.pending) {
          // A selected pair: the click moves that side's end (the pair stays selected, so the
          // other end can be moved next).
          landmarks.move(transfer.selected, pick.side, vertex);
        } else {
          landmarks.click(pick.side, vertex);
          transfer.selected = -1;
        }
        refresh();
      },
    });

    $('tr-landmarks-clear').addEventListener('click', () => {
      landmarks.clear();
      transfer.selected = -1;
      refresh();
    });

    const stem = (name) => name.replace(/^.*[\\/]/, '').replace(/\.[^.]*$/, '');
    $('tr-landmarks-save').addEventListener('click', () => {
      if (!meshes.reference || !meshes.source || !landmarks.pairs.length) return;
      const file = landmarkFile(landmarks.pairs, { reference: meshes.reference.info.name, source: meshes.source.info.name });
      transfer.saved = file;
      download(new TextEncoder().encode(`${JSON.stringify(file, null, 1)}\n`),
        `${stem(meshes.reference.info.name)}-${stem(meshes.source.info.name)}.json`, 'application/json');
    });

    $('tr-landmarks-load').addEventListener('change', async () => {
      const file = $('tr-landmarks-load').files[0];
      $('tr-landmarks-load').value = '';
      if (!file) return;
      if (!meshes.reference || !meshes.source) {
        app.showError({ code: 'InvalidArgument', message: 'load both meshes before their landmarks' });
        return;
      }
      try {
        const pairs = readLandmarkFile(JSON.parse(await file.text()), {
          referenceVertices: meshes.reference.info.weldedVertices, sourceVertices: meshes.source.info.weldedVertices,
        });
        landmarks.clear();
        landmarks.pairs.push(...pairs);
      } catch (e) {
        app.showError(e instanceof SyntaxError ? { code: 'ParseError', message: `${file.name}: ${e.message}` } : e);
        return;
      }
      transfer.selected = -1;
      refresh();
    });

    // ---- suggested pairs (extremities; worker op suggestLandmarks)

    const suggestionBody = root.querySelector('#tr-suggestions tbody');
    function setSuggestions(list) {
      transfer.suggestions = list.map((p) => [...p]);
      $('tr-suggestions').hidden = list.length === 0;
      suggestionBody.replaceChildren();
      list.forEach(([r, s], i) => {
        const row = fromHtml(`<tr data-index="${i}"><td class="pair-number suggested"></td><td>${r}</td><td>${s}</td>
          <td><button type="button" class="suggest-accept" title="Add this pair">✓</button> <button type="button" class="suggest-reject" title="Drop this suggestion">×</button></td></tr>`);
        const number = row.querySelector('.pair-number');
        number.textContent = `S${i + 1}`;
        number.style.borderColor = `rgb(${pairColor(landmarks.pairs.length + i).map((v) => Math.round(255 * v)).join(', ')})`;
        row.querySelector('.suggest-accept').addEventListener('click', () => acceptSuggestions([i]));
        row.querySelector('.suggest-reject').addEventListener('click', () => setSuggestions(transfer.suggestions.filter((_, k) => k !== i)));
        suggestionBody.append(row);
      });
      if (meshes.reference && meshes.source) {
        markers.showSuggestions(list.map(([r, s]) => [meshes.reference.weldedToRaw[r], meshes.source.weldedToRaw[s]]), landmarks.pairs.length);
      } else {
        markers.showSuggestions([], 0);
      }
    }

    function acceptSuggestions(indices) {
      const take = new Set(indices);
      const kept = [];
      transfer.suggestions.forEach(([r, s], i) => {
        if (take.has(i)) landmarks.pairs.push([r, s]);
        else kept.push([r, s]);
      });
      transfer.selected = -1;
      refresh();
      setSuggestions(kept);
    }

    $('tr-suggest').addEventListener('click', async () => {
      if (!meshes.reference || !meshes.source) {
        app.showError({ code: 'InvalidArgument', message: 'load the reference and the source first (steps 1 and 2)' });
        return;
      }
      const found = await app.runOp('Finding extremities', 'suggestLandmarks', {
        referenceSlot: slots.reference, sourceSlot: slots.source, sameConnectivity: transfer.sameConnectivity,
      });
      if (!found) return;
      // Pairs already listed are not suggested again.
      const taken = new Set(landmarks.pairs.map(([r, s]) => `${r}/${s}`));
      const fresh = found.info.pairs.filter(([r, s]) => !taken.has(`${r}/${s}`));
      setSuggestions(fresh.map(([r, s]) => [r, s]));
      app.setStatus(fresh.length ? `${fresh.length} suggested pairs: accept (✓) or reject (×) each` : 'no matching extremities found: click pairs yourself');
    });
    $('tr-suggest-accept-all').addEventListener('click', () => acceptSuggestions(transfer.suggestions.map((_, i) => i)));
    $('tr-suggest-reject-all').addEventListener('click', () => setSuggestions([]));

    // ---- view: side by side, split (linked or independent cameras), overlay

    function setView(mode) {
      transfer.view = mode;
      transfer.linked = $('tr-link').checked;
      $('tr-link-row').hidden = mode !== 'split';
      pair.setMode(mode, { linked: transfer.linked });
      showPaneLabels();
    }
    for (const radio of root.querySelectorAll('input[name="tr-view"]')) radio.addEventListener('change', () => setView(radio.value));
    $('tr-link').addEventListener('change', () => setView(transfer.view));
    $('tr-materials').addEventListener('change', () => pair.setMaterialMode($('tr-materials').checked ? 'document' : 'analysis'));

    // Names on the panes (split) or the halves (side by side).
    const paneLabels = fromHtml('<div class="pane-labels" hidden><span>Reference</span><span>Source</span></div>');
    viewer.renderer.domElement.after(paneLabels);
    function showPaneLabels() {
      paneLabels.hidden = !visible || transfer.view !== 'split';
      paneLabels.classList.toggle('split', transfer.view === 'split');
    }

    // ---- files dropped on the view while this job is shown: the left half opens the
    // reference, the right half the source (never the Mesh job's mesh)

    const dropSide = (x) => {
      const rect = viewer.renderer.domElement.getBoundingClientRect();
      return x < rect.left + rect.width / 2 ? 'reference' : 'source';
    };
    app.onDrop('transfer', {
      describe: (x) => `Drop here to open the ${dropSide(x)} (${dropSide(x) === 'reference' ? 'left' : 'right'} half)`,
      async drop(fileList, x) {
        const side = dropSide(x);
        if (transfer.loading) {
          app.refuse({ code: 'Busy', message: `The ${transfer.loading} is still loading: the dropped file was not opened. Drop it again when it has loaded.` });
          return;
        }
        try {
          if (await loadSide(side, await userFiles(fileList))) $(`tr-${side}-sample`).value = 'file';
        } catch (e) {
          app.showError(e);
        }
      },
    });

    // ---- run, compare, show

    function clearResult() {
      result = null;
      resultRaw = null;
      level1 = null;
      level1Raw = null;
      partColors = null;
      transfer.result = null;
      gammaMap.hide();
      showParts();
      if (meshes.source) showSource();
    }

    $('tr-run').addEventListener('click', async () => {
      if (!meshes.reference || !meshes.source) {
        app.showError({ code: 'InvalidArgument', message: 'load the reference and the source first (steps 1 and 2)' });
        return;
      }
      if (!landmarksReady()) {
        app.showError({ code: 'InvalidArgument', message: `the transfer needs at least ${minLandmarks} landmark pairs (${landmarks.pairs.length} given)${transfer.sameConnectivity ? '; with none, same-connectivity pairs get generated ones' : ''}` });
        return;
      }
      const method = $('tr-method').value;
      const options = { referenceSlot: slots.reference, sourceSlot: slots.source, method, ...(form ? form.values() : {}) };
      if (landmarks.pairs.length) options.landmarks = landmarks.pairs.map((p) => [...p]);
      const partsMode = $('tr-parts').value;
      if (partsMode === 'file' && !transfer.partsFile) {
        app.showError({ code: 'InvalidArgument', message: 'Parts: from file, but no part file is loaded (Load parts…)' });
        return;
      }
      const withParts = partsMode !== 'none';
      const ran = withParts
        ? await app.runOp(`Part transfer (${method}, ${partsMode === 'auto' ? 'automatic parts' : transfer.partsFile.name})`, 'partTransfer', {
          ...options, parts: partsMode === 'auto' ? 'auto' : transfer.partsFile.text, partOptions: partForm ? partForm.values() : {},
        })
        : await app.runOp(`Pose transfer (${method})`, 'transfer', options);
      if (!ran) return;
      const positions = ran.buffers.positions;
      // compare: the result against the source (flipped faces, detail change); for
      // same-connectivity pairs also against the reference (how close the pose came).
      const metrics = await app.runOp('Comparing with the source', 'compare', { slotB: slots.source }, { positionsA: positions.slice() });
      if (!metrics) return;
      const toReference = transfer.sameConnectivity
        ? await app.runOp('Comparing with the reference', 'compare', { slotB: slots.reference }, { positionsA: positions.slice() })
        : null;
      result = positions;
      resultRaw = unweldValues(positions, meshes.source.toWelded, 3);
      level1 = withParts ? ran.buffers.positionsLevel1 : null;
      level1Raw = withParts ? unweldValues(ran.buffers.positionsLevel1, meshes.source.toWelded, 3) : null;
      partColors = withParts ? partRegionColors(ran.buffers.partLabels, meshes.source.toWelded) : null;
      transfer.runs += 1;
      transfer.method = method;
      transfer.result = {
        info: withParts ? ran.info.level1 : ran.info, metrics: metrics.info, toReference: toReference?.info ?? null,
        options: { ...options, landmarks: options.landmarks ? options.landmarks.length : 'generated', parts: partsMode },
        parts: withParts ? { info: { ...ran.info, level1: undefined } } : null,
      };
      transfer.showing = 'result';
      root.querySelector('input[name="tr-show"][value="result"]').checked = true;
      showSource();
      pair.frame();
      showResultInfo();
      showParts();
      refresh();
      app.setStatus(withParts
        ? `part transfer (${method}): ${fixed(ran.info.ms.total / 1000, 3)} s, ${keptParts(ran.info.parts).length} of ${ran.info.parts.length} parts kept`
        : `transfer (${method}): ${fixed(ran.info.ms.total / 1000, 3)} s`);
    });

    function showResultInfo() {
      const { info, metrics, toReference, options } = transfer.result;
      const lowFrequencies = options.num_low_frequencies ?? form?.controls.get('num_low_frequencies')?.option.default ?? 5;
      gammaMap.show(info.gamma, info.k, lowFrequencies + 1);
      const rows = [
        ['Γ dominance', `${fixed(info.gammaDominance)} (min |Γᵢᵢ| / Σⱼ≠ᵢ |Γᵢⱼ| over the first K+1 rows)`],
        ['flipped faces', `${metrics.flippedFaces} (result against the source)${metrics.collapsedFaces ? `; ${metrics.collapsedFaces} collapsed (crushed below 1/1000 of their area)` : ''}`],
        ['detail change', `${fixed(metrics.laplacianChange)} (mean change of |Laplacian coordinates| against the source)`],
        ['moved', `mean ${fixed(metrics.vertexErrorMean)}, max ${fixed(metrics.vertexErrorMax)} × bbox diagonal from the source`],
      ];
      if (toReference) rows.push(['to reference', `mean ${fixed(toReference.vertexErrorMean)} × diagonal (same connectivity: the reference's pose itself)`]);
      rows.push(['solve', `${options.method}: ${options.method === 'yin' ? `${info.iterations} cage iterations${info.converged ? '' : ' (cap reached)'}, ` : ''}${info.couplingIterations} coupling steps, ${fixed(info.ms.total / 1000)} s`]);
      const parts = transfer.result.parts?.info;
      const retry = parts ? parts.foldRetry : info.foldRetry;
      if (retry?.tried) {
        rows.push(['folds', `the first result had ${retry.firstFlips} flipped face${retry.firstFlips === 1 ? '' : 's'} and ${retry.firstSelfIntersections} self-intersecting triangle pairs (the inputs ${retry.inputSelfIntersections}): ${parts ? 'level 1 and its parts ran again' : 'the cage was built again'} on a ${retry.resolution}-cell grid, ${retry.kept ? 'kept' : 'not kept (no fewer folds)'} (${fixed(retry.ms / 1000)} s)`]);
      }
      const repair = parts ? parts.flipRepair : info.flipRepair;
      if (repair?.tried) {
        rows.push(['flip repair', `${repair.flippedBefore} flipped face${repair.flippedBefore === 1 ? '' : 's'}${repair.collapsedBefore ? ` and ${repair.collapsedBefore} collapsed` : ''} solved again around them: ${repair.kept ? `kept (${repair.movedVertices} vertices moved)` : 'not kept (no fewer folds)'} (${fixed(repair.ms / 1000)} s)`]);
      }
      if (parts) {
        const kept = keptParts(parts.parts).length;
        rows.push(['parts', `${kept} of ${parts.parts.length} kept (level 1 ${fixed(parts.ms.level1 / 1000)} s, parts ${fixed(parts.ms.parts / 1000)} s)`]);
        const f = parts.folds;
        rows.push(['self-intersections', `result ${f.result}, level 1 ${f.level1} (reference ${f.reference} + source ${f.source}); flipped faces ${f.flips} (level 1 ${f.flipsLevel1})${f.collapsed || f.collapsedLevel1 ? `; collapsed faces ${f.collapsed} (level 1 ${f.collapsedLevel1})` : ''}`]);
      }
      const list = $('tr-metrics');
      list.replaceChildren();
      for (const [term, text] of rows) {
        list.append(Object.assign(document.createElement('dt'), { textContent: term }), Object.assign(document.createElement('dd'), { textContent: text }));
      }
    }

    // The parts of a parts run: a table (status from the core) and a colour per part region.
    function showParts() {
      const parts = transfer.result?.parts?.info;
      $('tr-parts-result').hidden = !parts;
      $('tr-show-level1').hidden = !parts;
      $('tr-parts-save').disabled = !parts;
      const body = root.querySelector('#tr-parts-result tbody');
      body.replaceChildren();
      const proposals = parts?.proposals;
      $('tr-parts-proposals').hidden = !(proposals?.tried > 1);
      if (proposals?.tried > 1)
        $('tr-parts-proposals').textContent = `${proposals.tried} proposal sets tried (cuts nearer and farther from the tips) in ${proposals.rounds > 1 ? `${proposals.rounds} rounds, each on the result of the one before` : '1 round'}; set ${proposals.kept + 1} of the first kept: landmark error ${fixed(proposals.landmarkErrorLevel1, 4)} → ${fixed(proposals.landmarkError, 4)}`;
      if (!parts) return;
      parts.parts.forEach((p, i) => {
        // The cell says what happened; why (the core's message) is in the row's tooltip, so that
        // the table stays one line per part.
        let outcome = p.rigid ? 'kept (rigid)' : 'kept';
        if (p.rejected) outcome = 'rejected';
        else if (!p.ok) outcome = 'skipped';
        const row = fromHtml(`<tr><td class="part-chip"></td><td></td><td>${p.level}${p.round > 1 ? ` r${p.round}` : ''}</td><td class="outcome"></td><td>${p.sourceVertexCount}</td><td>${fixed(p.rotationDegrees, 2)}°</td></tr>`);
        const chip = row.querySelector('.part-chip');
        chip.textContent = String(i + 1);
        chip.style.background = `rgb(${pairColor(i).map((v) => Math.round(255 * v)).join(', ')})`;
        // Proposed parts are named "auto 2 (disagreement 110.2 at vertex 6205)": the short name in
        // the table, the rest and the timings as the row's tooltip.
        const short = p.name.replace(/\s*\(.*\)\s*$/, '') || p.name;
        row.children[1].textContent = short;
        const registration = p.rigid ? `its transfer folded ${p.transferFlips} faces, so it was turned rigidly onto its landmarks: rotation` : 'frame rotation';
        row.title = `${p.name}: ${p.ok ? '' : `${p.message.replace(/^rejected: /, '')}. `}${p.subdivisions} subdivision(s), ${p.landmarks} landmarks, ${p.cageReused ? `level-1 cage (${p.fixedCageVertices} of its vertices held)` : 'own cage'}, ${registration} ${fixed(p.rotationDegrees)}°, seam dihedral change mean ${fixed(p.seamDihedralMean)}° max ${fixed(p.seamDihedralMax)}°, ${fixed(p.ms / 1000)} s`;
        row.querySelector('.outcome').textContent = outcome;
        row.classList.toggle('rejected', !outcome.startsWith('kept'));
        body.append(row);
      });
    }

    $('tr-part-colours').addEventListener('change', () => showSource());

    function showPartsHint() {
      const mode = $('tr-parts').value;
      transfer.parts = mode;
      let hint = '';
      if (mode === 'auto') hint = 'After the whole-body transfer, parts where the pose still disagrees most (limbs, head, tail) are proposed with cuts at several distances from their tips, transferred again and glued back, and the set whose landmarks land closest to the reference is kept; then parts are proposed again on that result, for up to 3 rounds; a part that would add folds, flips or a seam is rejected. Save parts gives the parts used, to edit.';
      else if (mode === 'file') hint = `${transfer.partsFile.count} part pair${transfer.partsFile.count === 1 ? '' : 's'} from ${transfer.partsFile.name}.`;
      $('tr-parts-hint').textContent = hint;
      if (partForm) partForm.element.hidden = mode === 'none';
    }
    $('tr-parts').addEventListener('change', showPartsHint);

    $('tr-parts-load').addEventListener('change', async () => {
      const file = $('tr-parts-load').files[0];
      $('tr-parts-load').value = '';
      if (!file) return;
      const text = await file.text();
      let count = 0;
      try {
        const countPairs = (list) => (Array.isArray(list) ? list.reduce((n, p) => n + 1 + countPairs(p?.children), 0) : 0);
        const parsed = JSON.parse(text);
        if (!Array.isArray(parsed?.parts) || parsed.parts.length === 0) throw new Error('no "parts" array with at least one part pair');
        count = countPairs(parsed.parts);
      } catch (e) {
        app.showError({ code: 'ParseError', message: `${file.name}: ${e.message} (a part file is {"parts": [{"name", "source": {"disk": {"seed", "radius"}} | {"plane": ...}, "reference"?, "children"?}]})` });
        return;
      }
      transfer.partsFile = { name: file.name, text, count };
      const option = $('tr-parts').querySelector('option[value="file"]');
      option.disabled = false;
      option.textContent = `from ${file.name}`;
      $('tr-parts').value = 'file';
      showPartsHint();
    });

    $('tr-parts-save').addEventListener('click', () => {
      const parts = transfer.result?.parts?.info;
      if (!parts || !meshes.reference || !meshes.source) return;
      download(new TextEncoder().encode(parts.partsJson), `${stem(meshes.reference.info.name)}-${stem(meshes.source.info.name)}-parts.json`, 'application/json');
    });

    for (const radio of root.querySelectorAll('input[name="tr-show"]')) {
      radio.addEventListener('change', () => {
        transfer.showing = radio.value;
        showSource();
      });
    }

    $('tr-export').addEventListener('click', async () => {
      if (!result) return;
      const exported = await app.runOp('Exporting GLB', 'export', { slot: slots.source, format: 'glb' }, { positions: result.slice() });
      if (!exported) return;
      download(exported.buffers.bytes, exported.info.fileName.replace(/\.glb$/, '-posed.glb'), 'model/gltf-binary');
      transfer.exports += 1;
    });

    // ---- wiring

    app.on('ready', async () => {
      try {
        const schema = (await client.run('optionSchema', { job: 'transfer' }).promise).info;
        // The method has its own selector above the form: its choices, default and help come
        // from the schema too (the labels above only name the papers).
        const method = schema.options.find((o) => o.name === 'method');
        if (method) {
          const select = $('tr-method');
          for (const choice of method.choices || []) {
            if (![...select.options].some((o) => o.value === choice)) select.add(new Option(choice, choice));
          }
          for (const o of [...select.options]) if (!(method.choices || []).includes(o.value)) o.remove();
          select.value = method.default;
          select.title = method.help;
        }
        form = new OptionsForm(schema.options.filter((o) => o.name !== 'method'), { title: 'Transfer options' });
        $('tr-options').append(form.element);
        const partSchema = (await client.run('optionSchema', { job: 'transfer-parts' }).promise).info;
        partForm = new OptionsForm(partSchema.options, { title: 'Part options' });
        $('tr-part-options').append(partForm.element);
        showPartsHint();
      } catch (e) {
        app.showError(e);
      }
      refresh();
    });
    app.on('job', (job) => {
      const was = visible;
      visible = job === 'transfer';
      if (visible === was) return;
      pair.setActive(visible);
      showPaneLabels();
      if (!visible) {
        hoverMarker.hide();
        viewer.frame(); // the Mesh / Edit jobs' mesh, framed as they left it
      }
    });
    // A mesh loaded in the Mesh job frames the camera on it; while the pair is shown, frame it.
    app.on('mesh', () => { if (visible) pair.frame(); });

    // tolerance: see view/screen-space.js vertexVisible (labels use labelTolerance).
    app.hooks.transferVertexOnScreen = (side, vertex, tolerance = undefined) => vertexOnScreen(viewer, vertex, { ...pair.sides[side], ...pair.view(side), tolerance });
    app.hooks.labelTolerance = labelTolerance;
    app.hooks.transferLabels = () => markers.labels();
    app.hooks.transferMaterials = () => pair.shownMaterials();
    app.hooks.transferCameras = () => [0, 1].map((i) => ({
      position: viewer.paneCamera(i).position.toArray(), target: (i ? viewer.controls2 : viewer.controls).target.toArray(),
    }));
    // Welded → raw for a side (tests place the pointer on displayed vertices).
    app.hooks.transferRawVertex = (side, welded) => meshes[side]?.weldedToRaw[welded] ?? -1;
    showParts();
    app.hooks.transferResult = () => (result ? Array.from(result) : null);
    app.hooks.transferLevel1 = () => (level1 ? Array.from(level1) : null);
    app.hooks.transferColors = () => {
      const c = pair.sides.source.mesh.geometry.getAttribute('color');
      return pair.sides.source.analysis.vertexColors && c ? Array.from(c.array) : null;
    };
    app.hooks.transferShown = (side = 'source') => Array.from(pair.sides[side].mesh.geometry.getAttribute('position').array);
    refresh();
    return root;
  },
};
