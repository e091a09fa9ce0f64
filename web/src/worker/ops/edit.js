// Worker ops of the edit module (bindings in wasm/bind_edit.cpp, core in core/edit): an
// interactive editing session on the mesh in a slot — create once per (ROI, handles, fixed)
// set, drag many times (fast preview), finalize when the user lets go, dispose when done.
// Listed in worker/ops/index.js like every ops file; see ops/mesh.js for the op signature
// `(ctx, options, buffers) => {info, buffers}` and ctx.state.
//
// Positions come back twice: `positions` on the welded mesh (#W·3, what core computed, what the
// export op takes) and `rawPositions` in the loaded file's vertex layout (#R·3, through the
// asset's toWelded map) for swapping into the three.js BufferGeometry directly, with
// `rawNormals` (smooth normals of the welded surface, raw layout, as the load op gives): the
// page's main thread does no per-vertex work while a gizmo is dragged.
import { vertexNormals } from '../../lib/arrays.js';
import { MeshMorphError, unwrap } from '../../lib/errors.js';
import { defaultSlot, meshInSlot } from './mesh.js';

function editSessions(ctx) {
  ctx.state.editSessions ??= new Map();
  return ctx.state.editSessions;
}

function sessionFor(ctx, slot) {
  const entry = editSessions(ctx).get(slot);
  if (!entry) throw new MeshMorphError('InvalidArgument', `no edit session on slot '${slot}'; call editCreate first`);
  return entry;
}

function disposeSession(ctx, slot) {
  const entry = editSessions(ctx).get(slot);
  if (!entry) return false;
  entry.session.dispose();
  entry.session.delete(); // embind handle
  editSessions(ctx).delete(slot);
  return true;
}

// Welded positions (Float32Array #W·3) → the raw layout of the loaded file (#R·3).
function unweld(positions, toWelded) {
  const raw = new Float32Array(toWelded.length * 3);
  for (let r = 0; r < toWelded.length; r++) {
    const w = toWelded[r] * 3;
    raw[3 * r] = positions[w];
    raw[3 * r + 1] = positions[w + 1];
    raw[3 * r + 2] = positions[w + 2];
  }
  return raw;
}

function positionsResult(ctx, entry, result, started, extraInfo = {}) {
  const r = unwrap(result);
  const normals = vertexNormals(r.positions, meshInSlot(ctx, entry.slot).weldedIndices);
  return {
    buffers: { positions: r.positions, rawPositions: unweld(r.positions, entry.toWelded), rawNormals: unweld(normals, entry.toWelded) },
    info: { slot: entry.slot, milliseconds: Date.now() - started, ...extraInfo },
  };
}

export const ops = {
  // options {slot?, spec: object | JSON string} — the edit spec of core/edit/edit_spec.h (roi,
  // fixed, handles with selections and transforms, features, options). Replaces a previous
  // session on the slot. → info {slot, handles: [vertex counts], stats, features, transforms:
  // the spec's transforms as column-major 4x4 arrays, milliseconds}
  editCreate(ctx, options = {}) {
    const slot = options.slot || defaultSlot;
    if (options.spec === undefined) throw new MeshMorphError('InvalidArgument', 'editCreate needs options.spec');
    const mesh = meshInSlot(ctx, slot);
    disposeSession(ctx, slot);
    const started = Date.now();
    const session = new ctx.module.EditSession();
    let r;
    try {
      r = unwrap(session.create(mesh.weldedPositions, mesh.weldedIndices, options.spec,
        (stage, fraction) => ctx.progress(stage, fraction)));
    } catch (e) {
      session.delete();
      throw e;
    }
    editSessions(ctx).set(slot, { session, slot, toWelded: mesh.toWelded });
    return {
      buffers: {},
      info: {
        slot,
        handles: r.handles,
        stats: r.stats,
        features: r.features,
        transforms: r.transforms,
        vertices: r.vertices,
        milliseconds: Date.now() - started,
      },
    };
  },

  // options {slot?, transforms: [TRANSFORM per handle]} with TRANSFORM = {matrix: [16, column-
  // major]} (a three.js Matrix4's elements) or {translate, rotate: {axis, degrees}, pivot, scale}.
  // → buffers {positions, rawPositions}, info {slot, milliseconds}
  editDrag(ctx, options = {}) {
    const entry = sessionFor(ctx, options.slot || defaultSlot);
    if (!Array.isArray(options.transforms)) throw new MeshMorphError('InvalidArgument', 'editDrag needs options.transforms (one per handle)');
    const started = Date.now();
    return positionsResult(ctx, entry, entry.session.drag(options.transforms), started);
  },

  // options {slot?, preview?: true — one plain solve for the frames of a pointer drag, refine on
  // release}, buffers {targets: Float64Array #W·3 (only handle rows are read)}
  // → buffers {positions, rawPositions}
  editDragPositions(ctx, options = {}, buffers = {}) {
    const entry = sessionFor(ctx, options.slot || defaultSlot);
    if (!buffers.targets) throw new MeshMorphError('InvalidArgument', 'editDragPositions needs buffers.targets');
    const started = Date.now();
    return positionsResult(ctx, entry, entry.session.dragPositions(buffers.targets, options.preview === true), started);
  },

  // options {slot?, mode?: 'keep' | 'scale'} — shear removal and the second solve after a drag.
  // → buffers {positions, rawPositions}, info {slot, milliseconds}
  editFinalize(ctx, options = {}) {
    const entry = sessionFor(ctx, options.slot || defaultSlot);
    const started = Date.now();
    return positionsResult(ctx, entry, entry.session.finalize(options.mode), started, { mode: options.mode || 'spec' });
  },

  // options {slot?} → info {slot, disposed}
  editDispose(ctx, options = {}) {
    const slot = options.slot || defaultSlot;
    return { buffers: {}, info: { slot, disposed: disposeSession(ctx, slot) } };
  },
};
