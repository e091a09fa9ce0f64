// Worker ops of the mesh module (bindings in wasm/bind_mesh.cpp): load a file, report, the
// eigenbasis, export. Listed in worker/ops/index.js like every ops file; node tests (tests/js/)
// import this file and call the same functions with the node build of the module, so the page
// and the tests exercise one code path.
//
// An op is `(ctx, options, buffers) => {info, buffers}` where
//   ctx.module   the Emscripten module (meshmorph_web or meshmorph_node)
//   ctx.state    per-worker state shared by all op files; meshes live in ctx.state.meshes,
//                a Map slot → {asset, name, format, weldedVertices, weldedPositions, weldedIndices,
//                toWelded} (the welded arrays are fetched from the asset on first read)
//   ctx.progress (stage, fraction) => boolean; false means "cancel" and is handed to the
//                core's Progress sink, which stops with code Cancelled
// Options use the names of the job's options schema (optionSchema below; a missing field means
// the core's default, an unknown one is an error). Returned
// typed arrays are transferred to the caller.
import { MeshMorphError, unwrap } from '../../lib/errors.js';

export const defaultSlot = 'main';

// The loaded mesh in `slot`, or a readable error. Other op files use this to find their input.
export function meshInSlot(ctx, slot = defaultSlot) {
  const mesh = ctx.state.meshes?.get(slot);
  if (!mesh) throw new MeshMorphError('InvalidArgument', `no mesh is loaded${slot === defaultSlot ? '' : ` in slot '${slot}'`}; load a file first`);
  return mesh;
}

// A mesh slot whose weldedPositions / weldedIndices are copied out of the module's asset on
// first read (module.assetWeldedMesh) and then kept: loading a mesh only to view it never pays
// for them (at 1M vertices, 56 MB and a tenth of the load). Assigning them (a cut replaces the
// mesh) works as on a plain object.
function weldedMeshSlot(module, slot) {
  let welded = null;
  const fetch = () => (welded ??= { ...unwrap(module.assetWeldedMesh(slot.asset)) });
  const field = (key) => ({ get: () => fetch()[key], set: (value) => { fetch()[key] = value; }, enumerable: true });
  return Object.defineProperties(slot, { weldedPositions: field('positions'), weldedIndices: field('indices') });
}

function toBytes(value) {
  if (value instanceof Uint8Array) return value;
  if (value instanceof ArrayBuffer) return new Uint8Array(value);
  if (ArrayBuffer.isView(value)) return new Uint8Array(value.buffer, value.byteOffset, value.byteLength);
  return undefined;
}

export const ops = {
  // options {name, slot?, weld?: {tolerance, drop_degenerate_faces}, skip_unsupported_primitives?}
  // buffers {[options.name]: file bytes, [sibling uri]: bytes ...} — a .gltf's .bin and images
  // travel as siblings keyed by their file name.
  // → buffers {positions, indices, normals, toWelded} (raw layout, for display)
  //   info {slot, name, format, warnings, primitives, report, text, rawVertices, weldedVertices}
  load(ctx, options = {}, buffers = {}) {
    const name = options.name;
    if (typeof name !== 'string' || !name) throw new MeshMorphError('InvalidArgument', 'load needs options.name (the file name)');
    const bytes = toBytes(buffers[name]);
    if (!bytes) throw new MeshMorphError('InvalidArgument', `load: no bytes for '${name}'`);
    if (bytes.length === 0) throw new MeshMorphError('ParseError', `'${name}' is empty (0 bytes)`);
    const files = {};
    for (const [key, value] of Object.entries(buffers)) if (key !== name && toBytes(value)) files[key] = toBytes(value);

    const r = unwrap(ctx.module.loadAsset(bytes, name, files, {
      weld: options.weld,
      skip_unsupported_primitives: options.skip_unsupported_primitives,
    }));
    const slot = options.slot || defaultSlot;
    ctx.state.meshes ??= new Map();
    const previous = ctx.state.meshes.get(slot);
    if (previous) ctx.module.disposeAsset(previous.asset);
    ctx.state.meshes.set(slot, weldedMeshSlot(ctx.module, {
      asset: r.asset,
      name: r.name,
      format: r.format,
      weldedVertices: r.weldedVertices,
      toWelded: r.toWelded,
    }));
    return {
      buffers: { positions: r.positions, indices: r.indices, normals: r.normals, toWelded: r.toWelded.slice() },
      info: {
        slot,
        name: r.name,
        format: r.format,
        warnings: r.warnings,
        primitives: r.primitives,
        report: r.report,
        text: r.text,
        infoReport: r.info, // the `meshmorph info --json` object
        rawVertices: r.positions.length / 3,
        weldedVertices: r.weldedVertices,
      },
    };
  },

  // options {slot?} → info {slot, report, text} of the loaded (welded) mesh.
  // buffers {positions, indices} instead validates those arrays (no slot needed).
  validate(ctx, options = {}, buffers = {}) {
    let positions = buffers.positions;
    let indices = buffers.indices;
    if (!positions || !indices) {
      const mesh = meshInSlot(ctx, options.slot);
      positions = mesh.weldedPositions;
      indices = mesh.weldedIndices;
    }
    const r = unwrap(ctx.module.validateMesh(positions, indices, {
      degenerate_area_tolerance: options.degenerate_area_tolerance,
    }));
    return { buffers: {}, info: { slot: options.slot || defaultSlot, report: r.report, text: r.text } };
  },

  // Generalized eigenbasis Wφ = λAφ of the mesh in `slot` (core/spectral/spectral_basis.h).
  // options {slot?, k?, ncv?, relative_shift?, tolerance?, max_iterations?, solver?}
  // → buffers {eigenvalues: Float64Array k, vectors: Float32Array k·#W (function i at [i·#W, (i+1)·#W))}
  //   info {slot, k, weldedVertices, iterations, operations, solver, milliseconds}
  eigs(ctx, options = {}) {
    const mesh = meshInSlot(ctx, options.slot);
    const started = Date.now();
    const r = unwrap(ctx.module.spectralBasis(mesh.weldedPositions, mesh.weldedIndices, {
      k: options.k,
      ncv: options.ncv,
      relative_shift: options.relative_shift,
      tolerance: options.tolerance,
      max_iterations: options.max_iterations,
      solver: options.solver,
    }, (stage, fraction) => ctx.progress(stage, fraction)));
    return {
      buffers: { eigenvalues: r.eigenvalues, vectors: r.vectors },
      info: {
        slot: options.slot || defaultSlot,
        k: r.eigenvalues.length,
        weldedVertices: mesh.weldedPositions.length / 3,
        iterations: r.iterations,
        operations: r.operations,
        solver: r.solver,
        milliseconds: Date.now() - started,
      },
    };
  },

  // The options schema of a job (app/option_schema.h; the CLI's flags and --help come from it):
  // options {job: 'edit' | 'transfer' | 'retarget'} → info {job, summary, options: [{name, kind,
  // default, min?, max?, choices?, flag, help}]}. Options panels are generated from it.
  optionSchema(ctx, options = {}) {
    return { buffers: {}, info: unwrap(ctx.module.optionSchema(String(options.job ?? ''))).schema };
  },

  // Writes the asset in `slot` (default GLB) keeping everything the loaded document had.
  // options {slot?, format? = 'glb', recompute_normals?}; buffers {positions?} = new welded
  // positions (#W·3); without them the loaded geometry is written.
  // → buffers {bytes: Uint8Array}, info {fileName, format, byteLength}
  export(ctx, options = {}, buffers = {}) {
    const mesh = meshInSlot(ctx, options.slot);
    const format = options.format || 'glb';
    const r = unwrap(ctx.module.exportAsset(mesh.asset, buffers.positions, format, {
      recompute_normals: options.recompute_normals,
    }));
    const stem = mesh.name.replace(/^.*[\\/]/, '').replace(/\.[^.]*$/, '') || 'mesh';
    return {
      buffers: { bytes: r.bytes },
      info: { fileName: `${stem}.${format}`, format, byteLength: r.bytes.length },
    };
  },

  // options {slot?}: frees the asset in `slot`.
  unload(ctx, options = {}) {
    const slot = options.slot || defaultSlot;
    const mesh = ctx.state.meshes?.get(slot);
    if (mesh) {
      ctx.module.disposeAsset(mesh.asset);
      ctx.state.meshes.delete(slot);
    }
    return { buffers: {}, info: { slot, unloaded: Boolean(mesh) } };
  },
};
