// Worker ops of the Merge job (bindings in wasm/bind_merge.cpp: mergeMeshes, cutMesh,
// boundaryLoops; exportAssetWithMesh in wasm/bind_mesh.cpp; the job in app/merge_job.h).
// Listed in worker/ops/index.js like every ops file; see ops/mesh.js for the op signature.
//
// mergeOpen: options {slot, name, cuts?: [CUT, ...]}, buffers: the file (and siblings) as for
//   `load`. Loads the file into `slot` and applies the cuts in order, so one request describes
//   the slot completely (the page marks it restoreKey: a replacement worker replays it).
//   CUT = {plane: [px, py, pz, nx, ny, nz], keep?: [x, y, z]} | {disk: [vertex, radius]}
//   (vertex: welded index on the mesh as cut so far; radius in mesh units), as `meshmorph cut`.
//   After a cut the slot's welded mesh is the cut mesh (its asset, the loaded document, stays
//   for the export).
//   → buffers {positions (raw layout, Float32), indices, toWelded, welded (Float64 #W·3),
//              weldedIndices}
//     info {slot, name, format, rawVertices, weldedVertices, faces, loops: [[v, ...], ...],
//           cuts: [{vertices, faces, boundaryLoops}], load: the load op's info}
// merge: options {targetSlot, sourceSlot, spec: object | JSON string (the CLI's merge spec),
//   placement?: 16 numbers, column-major} — placement moves the source before the merge (the
//   configuration-dependent mode's gizmo; `meshmorph merge` gets the placed source as a file).
//   → buffers {positions: Float64Array (merged, #V·3), indices: Uint32Array (#F·3; the zip
//              faces are the last seams[i].zipFaces ones), sourcePositions (deformed source)}
//     info {vertices, faces, boundaryLoops (of the merged mesh), sourceOffset, stats, seams,
//           milliseconds}
// mergeExport: options {slot, format = 'glb', placement?}; buffers {positions, indices}
//   (a merged mesh) or none (the slot's current mesh: cut, placed) → the slot's document with
//   that geometry (exportAssetWithMesh) → buffers {bytes}, info {fileName, format, byteLength}
import { MeshMorphError, unwrap } from '../../lib/errors.js';
import { meshInSlot, ops as meshOps } from './mesh.js';

function loopsOf(ctx, indices, count) {
  return unwrap(ctx.module.boundaryLoops(indices, count)).loops.map((l) => Array.from(l));
}

function checkCut(cut, i) {
  const numbers = (v, n) => Array.isArray(v) && v.length === n && v.every(Number.isFinite);
  if (cut && numbers(cut.plane, 6) && (cut.keep === undefined || numbers(cut.keep, 3))) return { plane: cut.plane, keep: cut.keep };
  if (cut && numbers(cut.disk, 2) && Number.isInteger(cut.disk[0])) return { disk: cut.disk };
  throw new MeshMorphError('InvalidArgument', `cut ${i + 1} must be {plane: [px, py, pz, nx, ny, nz], keep?: [x, y, z]} or {disk: [vertex, radius]}`);
}

// Column-major 4x4 applied to #V·3 positions (Float64Array).
function transformed(positions, m) {
  if (!Array.isArray(m) || m.length !== 16 || !m.every(Number.isFinite)) throw new MeshMorphError('InvalidArgument', 'placement must be 16 numbers (a column-major 4x4 matrix)');
  const out = new Float64Array(positions.length);
  for (let i = 0; i < positions.length; i += 3) {
    const x = positions[i], y = positions[i + 1], z = positions[i + 2];
    out[i] = m[0] * x + m[4] * y + m[8] * z + m[12];
    out[i + 1] = m[1] * x + m[5] * y + m[9] * z + m[13];
    out[i + 2] = m[2] * x + m[6] * y + m[10] * z + m[14];
  }
  return out;
}

const stem = (name) => name.replace(/^.*[\\/]/, '').replace(/\.[^.]*$/, '') || 'mesh';

export const ops = {
  mergeOpen(ctx, options = {}, buffers = {}) {
    const { slot, name, cuts = [] } = options;
    if (typeof slot !== 'string' || !slot) throw new MeshMorphError('InvalidArgument', 'mergeOpen needs options.slot');
    if (!Array.isArray(cuts)) throw new MeshMorphError('InvalidArgument', 'cuts must be an array');
    const checked = cuts.map(checkCut);
    const loaded = meshOps.load(ctx, { name, slot }, buffers);
    const mesh = meshInSlot(ctx, slot);
    const cutInfo = [];
    for (let i = 0; i < checked.length; ++i) {
      if (!ctx.progress('cut', i / checked.length)) throw new MeshMorphError('Cancelled', 'cancelled');
      const c = ctx.module.cutMesh(mesh.weldedPositions, mesh.weldedIndices, checked[i]);
      if (!c.ok) {
        // The slot keeps the mesh as cut so far would be confusing: drop it, the caller shows
        // the error and keeps its previous state (it replays the previous request).
        ctx.module.disposeAsset(mesh.asset);
        ctx.state.meshes.delete(slot);
        throw new MeshMorphError(c.code || 'Internal', `cut ${i + 1}: ${c.message}`);
      }
      mesh.weldedPositions = c.positions;
      mesh.weldedIndices = c.indices;
      mesh.cut = true;
      cutInfo.push({ vertices: c.positions.length / 3, faces: c.indices.length / 3, boundaryLoops: c.boundaryLoops });
    }
    const count = mesh.weldedPositions.length / 3;
    let display;
    if (checked.length) {
      const toWelded = new Uint32Array(count);
      for (let v = 0; v < count; ++v) toWelded[v] = v;
      mesh.toWelded = toWelded;
      display = { positions: Float32Array.from(mesh.weldedPositions), indices: mesh.weldedIndices.slice(), toWelded: toWelded.slice() };
    } else {
      display = { positions: loaded.buffers.positions, indices: loaded.buffers.indices, normals: loaded.buffers.normals, toWelded: loaded.buffers.toWelded };
    }
    return {
      buffers: { ...display, welded: mesh.weldedPositions.slice(), weldedIndices: mesh.weldedIndices.slice() },
      info: {
        slot,
        name: loaded.info.name,
        format: loaded.info.format,
        rawVertices: display.positions.length / 3,
        weldedVertices: count,
        faces: mesh.weldedIndices.length / 3,
        loops: loopsOf(ctx, mesh.weldedIndices, count),
        cuts: cutInfo,
        load: { warnings: loaded.info.warnings, report: loaded.info.report },
      },
    };
  },

  merge(ctx, options = {}) {
    const { targetSlot, sourceSlot, spec, placement } = options;
    const target = meshInSlot(ctx, targetSlot);
    const source = meshInSlot(ctx, sourceSlot);
    if (spec === undefined || spec === null) throw new MeshMorphError('InvalidArgument', 'merge needs options.spec');
    const text = typeof spec === 'string' ? spec : JSON.stringify(spec);
    const sourcePositions = placement ? transformed(source.weldedPositions, placement) : source.weldedPositions;
    const started = performance.now();
    const r = unwrap(ctx.module.mergeMeshes(target.weldedPositions, target.weldedIndices, sourcePositions, source.weldedIndices, text,
      (stage, fraction) => ctx.progress(stage, fraction)));
    const milliseconds = performance.now() - started;
    const vertices = r.positions.length / 3;
    return {
      buffers: { positions: r.positions, indices: r.indices, sourcePositions: r.sourcePositions },
      info: {
        vertices,
        faces: r.indices.length / 3,
        boundaryLoops: loopsOf(ctx, r.indices, vertices).length,
        sourceOffset: r.sourceOffset,
        stats: r.stats,
        seams: r.seams,
        milliseconds,
      },
    };
  },

  mergeExport(ctx, options = {}, buffers = {}) {
    const mesh = meshInSlot(ctx, options.slot);
    const format = options.format || 'glb';
    let positions = buffers.positions;
    let indices = buffers.indices;
    if (!positions || !indices) {
      positions = options.placement ? transformed(mesh.weldedPositions, options.placement) : mesh.weldedPositions;
      indices = mesh.weldedIndices;
    }
    const r = unwrap(ctx.module.exportAssetWithMesh(mesh.asset, positions, indices, format));
    return { buffers: { bytes: r.bytes }, info: { fileName: `${stem(mesh.name)}.${format}`, format, byteLength: r.bytes.length } };
  },
};
