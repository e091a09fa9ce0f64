// The Mesh panel: open a mesh (gallery sample, file picker, drop on the view), wireframe,
// export as GLB, and vertex picking (hover shows the vertex under the pointer, click pins it).
// After a load it emits 'mesh' for the other panels. State it owns (window.__meshmorph.state):
//   mesh     {name, format, rawVertices, weldedVertices, toWelded, text} of the loaded mesh
//   loads    successful loads; exports: successful exports (tests wait on both)
//   pick     the vertex under the pointer (view/picking.js), null when off the mesh
//   pinned   the last clicked vertex, null until a click on the mesh
//   materials {available, textured, count, reason, shown ('document' | 'analysis')} of the
//            loaded mesh's own glTF materials (view/document-materials.js)
import { defaultSampleId, samples } from '../../lib/samples.js';
import { documentMaterials, disposeDocumentMaterials, isGltfName } from '../../view/document-materials.js';
import { attachPointerPicking } from '../../view/pointer-picking.js';
import { download } from '../download.js';
import { finder, fromHtml } from '../dom.js';
import { sampleFiles, userFiles } from '../files.js';

const markup = `
<section>
  <h2>Mesh</h2>
  <label class="row">Sample
    <select id="sample" data-idle></select>
  </label>
  <label class="button file">Open files…
    <input type="file" id="file" data-idle multiple accept=".glb,.gltf,.bin,.obj,.off,.ply,.png,.jpg,.jpeg,.webp,.ktx2" />
  </label>
  <p class="hint">or drop files on the view — a .gltf together with its .bin and textures</p>
  <div class="row">
    <label><input type="checkbox" id="wireframe" /> Wireframe</label>
    <label title="The file's own glTF materials and textures; off: the plain analysis surface"><input type="checkbox" id="materials" checked /> Materials</label>
    <button id="export" type="button" data-idle>Export GLB</button>
  </div>
  <p id="materials-note" class="hint"></p>
  <p id="credit" class="hint"></p>
  <div id="pick" class="pick">
    <div id="pick-hover" class="hint">Point at the mesh to pick a vertex; click to pin it.</div>
    <div id="pick-pinned" hidden></div>
  </div>
</section>`;

const hoverColor = 0xffd23f;
const pinnedColor = 0x39e6a0;

// Coordinates for the panel: 4 significant digits, no exponent for ordinary sizes.
const coordinate = (v) => String(Number(v.toPrecision(4)));

function describe(pick) {
  const index = pick.welded ?? pick.vertex;
  return `vertex #${index} (${pick.point.map(coordinate).join(', ')})`;
}

function details(pick) {
  return `displayed vertex ${pick.vertex}${pick.welded === null ? '' : `, welded vertex ${pick.welded}`}, face ${pick.face}`;
}

export const panel = {
  id: 'mesh',
  title: 'Mesh',
  create(app) {
    const { state, viewer, client } = app;
    Object.assign(state, { mesh: null, loads: 0, exports: 0, pick: null, pinned: null, materials: null });
    const root = fromHtml(markup);
    const $ = finder(root);

    // ---- vertex picking

    const hoverMarker = viewer.createMarker({ color: hoverColor });
    const pinnedMarker = viewer.createMarker({ color: pinnedColor });

    function showPicks() {
      const hover = $('pick-hover');
      if (state.pick) {
        hover.textContent = describe(state.pick);
        hover.title = details(state.pick);
        hover.className = 'pick-hover';
      } else {
        hover.textContent = 'Point at the mesh to pick a vertex; click to pin it.';
        hover.title = '';
        hover.className = 'hint';
      }
      const pinned = $('pick-pinned');
      pinned.hidden = !state.pinned;
      if (state.pinned) {
        pinned.textContent = `pinned: ${describe(state.pinned)}`;
        pinned.title = details(state.pinned);
      }
    }

    // Picking belongs to the Mesh job: other jobs (edit brush, transfer landmarks) use the same
    // canvas for their own clicks, so hover and pins are hidden while they are shown.
    let shown = true;
    app.on('job', (job) => {
      shown = job === 'mesh';
      state.pick = null;
      hoverMarker.hide();
      if (shown && state.pinned) pinnedMarker.show(state.pinned.point);
      else pinnedMarker.hide();
      showPicks();
    });

    attachPointerPicking(viewer, {
      onHover(pick) {
        if (!state.mesh || !shown) return;
        state.pick = pick;
        if (pick) hoverMarker.show(pick.point);
        else hoverMarker.hide();
        showPicks();
      },
      onClick(pick) {
        if (!state.mesh || !pick || !shown) return;
        state.pinned = pick;
        pinnedMarker.show(pick.point);
        showPicks();
      },
    });

    // ---- loading

    // files: [{name, bytes: Uint8Array}], the first one being the mesh file.
    async function loadFiles(files, { credit = '' } = {}) {
      const [main] = files;
      const buffers = {};
      for (const f of files) buffers[f.name] = f.bytes;
      // The worker gets the bytes (transferred); a glTF's display materials are read from a
      // copy on this thread once the load succeeded.
      const copies = isGltfName(main.name) ? files.map((f) => ({ name: f.name, bytes: f.bytes.slice() })) : null;
      const t0 = performance.now();
      const result = await app.runOp(`Loading ${main.name}`, 'load', { name: main.name }, buffers, { restoreKey: 'mesh:main' });
      if (!result) return false;
      const t1 = performance.now();
      const { buffers: b, info } = result;
      state.mesh = {
        name: info.name, format: info.format, rawVertices: info.rawVertices, weldedVertices: info.weldedVertices,
        toWelded: b.toWelded, text: info.text,
      };
      state.pick = null;
      state.pinned = null;
      state.loads += 1;
      viewer.setMesh(b, { open: info.report.boundaryLoopLengths.length > 0 || info.report.components === 0 });
      // Where a load's time goes (the e2e reports it for the 1M-vertex mesh): the worker op as
      // this thread saw it (transfers included) and building the view's geometry.
      state.lastLoadMs = { worker: t1 - t0, view: performance.now() - t1 };
      showPicks();
      showMaterials(copies, info);
      $('credit').textContent = credit;
      app.setStatus(`${info.name}: ${info.weldedVertices} vertices, ${info.report.faces} faces · ${client.runtimeSummary}`);
      app.emit('mesh', state.mesh);
      return true;
    }

    async function loadSample(id) {
      const sample = samples.find((s) => s.id === id) || samples[0];
      $('sample').value = sample.id;
      try {
        return await loadFiles(await sampleFiles(sample), { credit: `Sample: ${sample.credit}` });
      } catch (e) {
        app.showError(e);
        return false;
      }
    }

    async function loadUserFiles(fileList) {
      let files;
      const t0 = performance.now();
      try {
        files = await userFiles(fileList);
        state.lastReadMs = performance.now() - t0;
      } catch (e) {
        app.showError(e);
        return false;
      }
      const loaded = await loadFiles(files, { credit: `Your file: ${files[0].name}` });
      if (loaded) $('sample').value = '';
      return loaded;
    }

    for (const s of samples) $('sample').add(new Option(s.label, s.id));
    $('sample').add(new Option('(your file)', ''));
    $('sample').addEventListener('change', () => {
      if ($('sample').value) loadSample($('sample').value);
    });
    $('file').addEventListener('change', async () => {
      const files = $('file').files;
      if (files.length) await loadUserFiles(files);
      $('file').value = ''; // picking the same file again fires change again
    });

    // Files dropped on the view while the Mesh or Edit job is shown (the shell routes drops
    // to the shown job only).
    const dropTarget = {
      describe: () => 'Drop mesh files to open them',
      drop: (files) => loadUserFiles(files),
    };
    app.onDrop('mesh', dropTarget);
    app.onDrop('edit', { ...dropTarget, describe: () => 'Drop mesh files to open them (the edit starts over on the new mesh)' });

    $('wireframe').addEventListener('change', () => viewer.setWireframe($('wireframe').checked));

    // ---- the document's own materials (glTF) or the analysis material

    // `shown` is what the mesh is drawn with now (colours of another panel use the analysis
    // material whatever the toggle says).
    const materialState = (fields) => ({ ...fields, get shown() { return viewer.shownMaterial; } });
    async function showMaterials(files, info) {
      const loads = state.loads;
      state.materials = materialState({ available: false, textured: false, count: 0, reason: 'not a glTF file', pending: Boolean(files) });
      $('materials').disabled = true;
      $('materials-note').textContent = '';
      if (!files) return;
      const display = await documentMaterials(files, info.primitives, info.rawVertices);
      if (loads !== state.loads) { disposeDocumentMaterials(display); return; } // another mesh came meanwhile
      if (display.error) {
        state.materials = materialState({ available: false, textured: false, count: 0, reason: display.error });
        $('materials-note').textContent = `Materials not shown: ${display.error}.`;
        return;
      }
      viewer.setDocumentMaterials(display);
      state.materials = materialState({ available: true, textured: display.textured, count: display.materials.length, reason: '' });
      $('materials').disabled = false;
      $('materials-note').textContent = `${display.materials.length} material${display.materials.length === 1 ? '' : 's'}${display.textured ? ', textured' : ''}`
        + `${display.missing.length ? ` (missing images: ${display.missing.join(', ')})` : ''}.`;
      viewer.setMaterialMode($('materials').checked ? 'document' : 'analysis');
    }
    $('materials').addEventListener('change', () => viewer.setMaterialMode($('materials').checked ? 'document' : 'analysis'));

    // ---- export

    $('export').addEventListener('click', async () => {
      if (!state.mesh) return;
      const result = await app.runOp('Exporting GLB', 'export', { format: 'glb' });
      if (!result) return;
      download(result.buffers.bytes, result.info.fileName, 'model/gltf-binary');
      state.exports += 1;
    });

    app.on('ready', () => loadSample(app.params.get('sample') || defaultSampleId));
    return root;
  },
};
