// Page controller: wires the panel, the viewer and the worker client together. Geometry work
// happens in the worker (worker.js); this thread only shows results.
//
// URL parameters: ?sample=<id> (initial gallery mesh), ?cancel=terminate (use the
// terminate-and-respawn cancel even when SharedArrayBuffer is available; see client.js).
import { MeshMorphClient } from './client.js';
import { fieldColors } from './colormap.js';
import { defaultSampleId, samples } from './samples.js';
import { Viewer } from './viewer.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const meshExtensions = ['.glb', '.gltf', '.obj', '.off', '.ply'];

const viewer = new Viewer($('view'));
const client = new MeshMorphClient({
  createWorker: () => new Worker(new URL('./worker.js', import.meta.url), { type: 'module' }),
  cancelMode: params.get('cancel') === 'terminate' ? 'terminate' : 'auto',
  onStatus: (text) => console.warn(`[meshmorph] ${text}`),
});

// Everything the page shows, in one place (also read by the end-to-end tests via
// window.__meshmorph).
const state = {
  ready: false,
  busy: null,        // {id, label} of the running request
  mesh: null,        // {name, format, rawVertices, weldedVertices, toWelded, text}
  eigen: null,       // {eigenvalues, vectors, k, i}
  error: null,       // {code, message} of the last error shown
  loads: 0,          // successful loads (tests wait on it)
  exports: 0,
};
window.__meshmorph = {
  state,
  client,
  get frames() { return viewer.frames; },
  // Resolves once a frame showing the current state has been drawn (tests read pixels then).
  nextFrame: () => new Promise((resolve) => {
    viewer.requestRender();
    requestAnimationFrame(() => requestAnimationFrame(resolve));
  }),
  get cancelMode() { return client.cancelMode; },
  get restarts() { return client.restarts; },
};

// ---- status, progress, errors

function setStatus(text) { $('status').textContent = text; }

function showError(error) {
  const code = error?.code || 'Error';
  const message = error?.message || String(error);
  state.error = { code, message };
  $('error-code').textContent = code;
  $('error-message').textContent = message;
  $('error').hidden = false;
  console.error(`[meshmorph] ${code}: ${message}`);
}

function clearError() {
  $('error').hidden = true;
}

function setBusy(busy) {
  state.busy = busy;
  $('progress').hidden = !busy;
  if (busy) {
    $('progress-label').textContent = busy.label;
    $('progress-bar').value = 0;
  }
  for (const id of ['sample', 'file', 'export', 'eig-run', 'eig-k']) $(id).disabled = Boolean(busy) || !state.ready;
  $('file').parentElement.classList.toggle('disabled', Boolean(busy) || !state.ready);
}

// Runs one worker op with the progress bar and Cancel button; errors are shown, not thrown
// (returns null), so every caller leaves the page usable.
async function runOp(label, op, options, buffers, extra = {}) {
  clearError();
  const { id, promise } = client.run(op, options, buffers, {
    ...extra,
    onProgress: (stage, fraction) => {
      $('progress-label').textContent = `${label} · ${stage} ${Math.round(fraction * 100)}%`;
      $('progress-bar').value = fraction;
    },
  });
  setBusy({ id, label });
  try {
    return await promise;
  } catch (e) {
    showError(e);
    return null;
  } finally {
    setBusy(null);
  }
}

$('cancel').addEventListener('click', () => {
  if (state.busy) client.cancel(state.busy.id);
});
$('error-close').addEventListener('click', clearError);

// ---- loading

// files: [{name, bytes: Uint8Array}], the first one being the mesh file.
async function loadFiles(files, { credit = '' } = {}) {
  const [main] = files;
  const buffers = {};
  for (const f of files) buffers[f.name] = f.bytes;
  const result = await runOp(`Loading ${main.name}`, 'load', { name: main.name }, buffers, { restoreKey: 'mesh:main' });
  if (!result) return false;
  const { buffers: b, info } = result;
  state.mesh = {
    name: info.name, format: info.format, rawVertices: info.rawVertices, weldedVertices: info.weldedVertices,
    toWelded: b.toWelded, text: info.text,
  };
  state.eigen = null;
  state.loads += 1;
  viewer.setMesh(b, { open: info.report.boundaryLoopLengths.length > 0 || info.report.components === 0 });
  resetEigenPanel();
  $('info').textContent = info.text;
  $('credit').textContent = credit;
  setStatus(`${info.name}: ${info.weldedVertices} vertices, ${info.report.faces} faces · cancel: ${client.cancelMode}`);
  return true;
}

async function fetchBytes(url) {
  const response = await fetch(url);
  if (!response.ok) throw Object.assign(new Error(`could not fetch ${url}: HTTP ${response.status}`), { code: 'IoError' });
  return new Uint8Array(await response.arrayBuffer());
}

async function loadSample(id) {
  const sample = samples.find((s) => s.id === id) || samples[0];
  $('sample').value = sample.id;
  const dir = sample.path.slice(0, sample.path.lastIndexOf('/') + 1);
  try {
    const names = [sample.path, ...(sample.files || []).map((f) => dir + f)];
    const bytes = await Promise.all(names.map((n) => fetchBytes(new URL(`samples/${n}`, document.baseURI))));
    const files = names.map((n, i) => ({ name: n.slice(n.lastIndexOf('/') + 1), bytes: bytes[i] }));
    return await loadFiles(files, { credit: `Sample: ${sample.credit}` });
  } catch (e) {
    showError(e);
    return false;
  }
}

function isMeshFile(name) {
  const lower = name.toLowerCase();
  return meshExtensions.some((ext) => lower.endsWith(ext));
}

// Files from the picker or a drop: the first mesh file is opened, the others are offered to
// it as siblings (a .gltf's buffers and images).
async function loadUserFiles(fileList) {
  const list = [...fileList];
  const main = list.find((f) => isMeshFile(f.name));
  if (!main) {
    showError({ code: 'Unsupported', message: `none of ${list.map((f) => f.name).join(', ')} is a mesh file (expected ${meshExtensions.join(', ')})` });
    return false;
  }
  const ordered = [main, ...list.filter((f) => f !== main)];
  const files = await Promise.all(ordered.map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
  const loaded = await loadFiles(files, { credit: `Your file: ${main.name}` });
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
const viewport = $('viewport');
let dragDepth = 0;
viewport.addEventListener('dragenter', (e) => { e.preventDefault(); dragDepth += 1; $('drop-overlay').hidden = false; });
viewport.addEventListener('dragleave', () => { dragDepth = Math.max(0, dragDepth - 1); if (!dragDepth) $('drop-overlay').hidden = true; });
viewport.addEventListener('dragover', (e) => e.preventDefault());
viewport.addEventListener('drop', (e) => {
  e.preventDefault();
  dragDepth = 0;
  $('drop-overlay').hidden = true;
  if (state.busy) return;
  if (e.dataTransfer?.files?.length) loadUserFiles(e.dataTransfer.files);
});

$('wireframe').addEventListener('change', () => viewer.setWireframe($('wireframe').checked));

// ---- eigenfunctions

function resetEigenPanel() {
  $('eig-i').disabled = true;
  $('eig-i').max = 0;
  $('eig-i').value = 0;
  $('eig-i-out').textContent = '–';
  $('eig-value').textContent = 'Colour the mesh by the i-th basis function of Wφ = λAφ.';
  $('eig-clear').disabled = true;
}

function showEigenfunction(i) {
  const e = state.eigen;
  if (!e || !state.mesh) return;
  e.i = Math.max(0, Math.min(e.k - 1, i));
  const n = state.mesh.weldedVertices;
  viewer.setColors(fieldColors(e.vectors.subarray(e.i * n, (e.i + 1) * n), state.mesh.toWelded));
  $('eig-i').value = e.i;
  $('eig-i-out').textContent = `${e.i}`;
  $('eig-value').textContent = `λ${subscript(e.i)} = ${e.eigenvalues[e.i].toPrecision(6)} (of ${e.k}; computed in ${e.milliseconds} ms)`;
}

function subscript(i) {
  return String(i).replace(/\d/g, (d) => '₀₁₂₃₄₅₆₇₈₉'[d]);
}

$('eig-run').addEventListener('click', async () => {
  if (!state.mesh) return;
  const k = Number($('eig-k').value);
  const result = await runOp(`Eigenbasis k = ${k}`, 'eigs', { k });
  if (!result) return;
  state.eigen = {
    eigenvalues: result.buffers.eigenvalues, vectors: result.buffers.vectors, k: result.info.k,
    milliseconds: result.info.milliseconds, i: 0,
  };
  $('eig-i').max = state.eigen.k - 1;
  $('eig-i').disabled = false;
  $('eig-clear').disabled = false;
  showEigenfunction(Math.min(1, state.eigen.k - 1)); // φ₀ is constant; φ₁ is the first interesting one
});
$('eig-i').addEventListener('input', () => showEigenfunction(Number($('eig-i').value)));
$('eig-clear').addEventListener('click', () => {
  viewer.setColors(null);
  $('eig-clear').disabled = true;
  if (state.eigen) state.eigen.i = -1;
});

// ---- export

function download(bytes, fileName, type) {
  const url = URL.createObjectURL(new Blob([bytes], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = fileName;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

$('export').addEventListener('click', async () => {
  if (!state.mesh) return;
  const result = await runOp('Exporting GLB', 'export', { format: 'glb' });
  if (!result) return;
  download(result.buffers.bytes, result.info.fileName, 'model/gltf-binary');
  state.exports += 1;
});

// ---- start

setBusy(null);
client.ready.then(
  async () => {
    state.ready = true;
    setBusy(null);
    setStatus(`ready · cancel: ${client.cancelMode}`);
    await loadSample(params.get('sample') || defaultSampleId);
  },
  (e) => {
    setStatus('the geometry module failed to start');
    showError(e);
  },
);
