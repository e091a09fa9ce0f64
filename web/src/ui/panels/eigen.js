// The Eigenfunctions panel (part of the Mesh job): computes the generalized eigenbasis
// Wφ = λAφ of the loaded mesh in the worker and colours the mesh by the i-th basis function.
// Re-colouring on every slider move happens here (lib/colormap.js), without the worker.
// State it owns (window.__meshmorph.state): eigen = {eigenvalues, vectors, k, milliseconds, solver, i}
// or null; reset when a new mesh loads.
import { fieldColors } from '../../lib/colormap.js';
import { finder, fromHtml } from '../dom.js';

const markup = `
<section>
  <h2>Eigenfunctions</h2>
  <div class="row">
    <label>k
      <select id="eig-k" data-idle>
        <option>10</option>
        <option selected>20</option>
        <option>50</option>
        <option>100</option>
      </select>
    </label>
    <button id="eig-run" type="button" data-idle>Compute basis</button>
  </div>
  <label class="row slider">i
    <input type="range" id="eig-i" min="0" max="0" value="0" disabled />
    <output id="eig-i-out">–</output>
  </label>
  <p id="eig-value" class="hint">Colour the mesh by the i-th basis function of Wφ = λAφ.</p>
  <button id="eig-clear" type="button" disabled>Plain surface</button>
</section>`;

function subscript(i) {
  return String(i).replace(/\d/g, (d) => '₀₁₂₃₄₅₆₇₈₉'[d]);
}

export const panel = {
  id: 'eigen',
  title: 'Eigenfunctions',
  job: 'mesh',
  create(app) {
    const { state, viewer } = app;
    state.eigen = null;
    const root = fromHtml(markup);
    const $ = finder(root);

    function reset() {
      $('eig-i').disabled = true;
      $('eig-i').max = 0;
      $('eig-i').value = 0;
      $('eig-i-out').textContent = '–';
      $('eig-value').textContent = 'Colour the mesh by the i-th basis function of Wφ = λAφ.';
      $('eig-clear').disabled = true;
    }

    function show(i) {
      const e = state.eigen;
      if (!e || !state.mesh) return;
      e.i = Math.max(0, Math.min(e.k - 1, i));
      const n = state.mesh.weldedVertices;
      viewer.setColors(fieldColors(e.vectors.subarray(e.i * n, (e.i + 1) * n), state.mesh.toWelded));
      $('eig-i').value = e.i;
      $('eig-i-out').textContent = `${e.i}`;
      $('eig-value').textContent = `λ${subscript(e.i)} = ${e.eigenvalues[e.i].toPrecision(6)} (of ${e.k}; computed in ${e.milliseconds} ms${e.solver ? `, ${e.solver}` : ''})`;
    }

    $('eig-run').addEventListener('click', async () => {
      if (!state.mesh) return;
      const k = Number($('eig-k').value);
      const result = await app.runOp(`Eigenbasis k = ${k}`, 'eigs', { k });
      if (!result) return;
      state.eigen = {
        eigenvalues: result.buffers.eigenvalues, vectors: result.buffers.vectors, k: result.info.k,
        milliseconds: result.info.milliseconds, solver: result.info.solver, i: 0,
      };
      $('eig-i').max = state.eigen.k - 1;
      $('eig-i').disabled = false;
      $('eig-clear').disabled = false;
      show(Math.min(1, state.eigen.k - 1)); // φ₀ is constant; φ₁ is the first interesting one
    });
    $('eig-i').addEventListener('input', () => show(Number($('eig-i').value)));
    $('eig-clear').addEventListener('click', () => {
      viewer.setColors(null);
      $('eig-clear').disabled = true;
      if (state.eigen) state.eigen.i = -1;
    });

    app.on('mesh', () => {
      state.eigen = null;
      reset();
    });
    return root;
  },
};
