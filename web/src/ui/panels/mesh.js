// The Mesh panel: open a mesh (gallery sample, file picker, drop on the view), wireframe,
// export as GLB, and vertex picking (hover shows the vertex under the pointer, click pins it).
// After a load it emits 'mesh' for the other panels. State it owns (window.__meshmorph.state):
//   mesh     {name, format, rawVertices, weldedVertices, toWelded, text} of the loaded mesh
//   loads    successful loads; exports: successful exports (tests wait on both)
//   pick     the vertex under the pointer (view/picking.js), null when off the mesh
//   pinned   the last clicked vertex, null until a click on the mesh
import { defaultSampleId, samples } from '../../lib/samples.js';
import { attachPointerPicking } from '../../view/pointer-picking.js';
import { download } from '../download.js';
import { finder, byId, fromHtml } from '../dom.js';
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
    <button id="export" type="button" data-idle>Export GLB</button>
  </div>
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
    Object.assign(state, { mesh: null, loads: 0, exports: 0, pick: null, pinned: null });
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
      const result = await app.runOp(`Loading ${main.name}`, 'load', { name: main.name }, buffers, { restoreKey: 'mesh:main' });
      if (!result) return false;
      const { buffers: b, info } = result;
      state.mesh = {
        name: info.name, format: info.format, rawVertices: info.rawVertices, weldedVertices: info.weldedVertices,
        toWelded: b.toWelded, text: info.text,
      };
      state.pick = null;
      state.pinned = null;
      state.loads += 1;
      viewer.setMesh(b, { open: info.report.boundaryLoopLengths.length > 0 || info.report.components === 0 });
      showPicks();
      $('credit').textContent = credit;
      app.setStatus(`${info.name}: ${info.weldedVertices} vertices, ${info.report.faces} faces · cancel: ${client.cancelMode}`);
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
      try {
        files = await userFiles(fileList);
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

    // Drag and drop on the view.
    const viewport = byId('viewport');
    const overlay = fromHtml('<div id="drop-overlay" hidden>Drop mesh files to open them</div>');
    byId('view').after(overlay);
    let dragDepth = 0;
    viewport.addEventListener('dragenter', (e) => { e.preventDefault(); dragDepth += 1; overlay.hidden = false; });
    viewport.addEventListener('dragleave', () => { dragDepth = Math.max(0, dragDepth - 1); if (!dragDepth) overlay.hidden = true; });
    viewport.addEventListener('dragover', (e) => e.preventDefault());
    viewport.addEventListener('drop', (e) => {
      e.preventDefault();
      dragDepth = 0;
      overlay.hidden = true;
      if (state.busy) return;
      if (e.dataTransfer?.files?.length) loadUserFiles(e.dataTransfer.files);
    });

    $('wireframe').addEventListener('change', () => viewer.setWireframe($('wireframe').checked));

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
