// Worker ops of the transfer module (bindings in wasm/bind_transfer.cpp): spectral pose transfer
// (paper 000) between two loaded meshes, and the comparison metrics. Listed in
// worker/ops/index.js like every ops file.
//
// transfer: options {referenceSlot = 'reference', sourceSlot = 'main', landmarks?: [[r, s], ...],
//   ...any option of optionSchema {job: 'transfer'} (method, lambda1, lambda2, num_low_frequencies,
//   num_eigenpairs, num_coupled, mu, cage_vertices, cage_resolution, max_iterations, tolerance,
//   placement); a missing one is the core's default, an unknown one an InvalidArgument error};
//   buffers {cagePositions?, cageIndices?}: the user's closed cage around the source (default automatic)
//   → buffers {positions: Float32Array (welded #V·3 of the source), cagePositions, cageIndices}
//     info {gammaDominance, iterations, converged, couplingIterations, ms, k, gamma: number[],
//       foldRetry {tried, kept, resolution, firstFlips, firstCollapsed, firstSelfIntersections,
//       inputSelfIntersections, ms} (the first result folded: the cage was built on a finer grid),
//       flipRepair {tried, kept, flippedBefore, collapsedBefore, movedVertices, ms} (the result still
//       flipped or collapsed faces:
//       their neighbourhood was solved again: transfer/flip_repair.h)}
//   Progress messages carry the core's stages (eigenbasis, coupled bases, cage: …,
//   mean-value coordinates, optimisation); returning false from ctx.progress cancels.
// partTransfer: hierarchical part transfer (paper 000 Sec. 4.3): the whole-body transfer, then
//   part pairs transferred again and glued back. options as for transfer, plus
//   {parts: 'auto' (proposed parts) | the text of a part file (the CLI's --parts JSON),
//    partOptions: options of optionSchema {job: 'transfer-parts'}}
//   → buffers {positions (final, welded #V·3), positionsLevel1, partLabels: Int32Array (per
//     welded source vertex the index of the deepest part that contains it, -1 outside)}
//     info {level1: the transfer op's info for level 1, partsJson (the parts used: the kept
//     proposal set with 'auto'), proposals {tried, kept, rounds, landmarkErrorLevel1, landmarkError}
//     (automatic parts: how many proposal sets were transferred and which one was kept),
//     parts: [{name, level, round, ok, message, rejected, sourceVertexCount,
//     referenceVertices, subdivisions, landmarks, rotationDegrees, rigid, transferFlips (a part
//     whose own transfer folded faces is turned rigidly onto its landmarks), cageReused,
//     fixedCageVertices (its transfer ran in the level-1 cage, this many cage vertices held),
//     seamDihedralMean,
//     seamDihedralMax, ms}] (transfer order, depth first), folds {reference, source, level1,
//     result, flipsLevel1, flips, collapsedLevel1, collapsed}, foldRetry and flipRepair (as transfer's, for the whole
//     two-level run),
//     ms {level1, parts, total}}
// compare: options {slotA = 'main', slotB = 'reference'} (same vertex order); buffers
//   {positionsA?: welded #V·3} compares those positions (e.g. a transfer result) instead of slotA's
//   → info {vertexErrorMean, vertexErrorMax, laplacianChange, edgeDistortionMean,
//           edgeDistortionMax, flippedFaces, collapsedFaces}
// suggestLandmarks: options {referenceSlot = 'reference', sourceSlot = 'main', count = 8,
//   sameConnectivity?: the meshes share vertex order (then a reference extremity pairs with the
//   same vertex)} → info {pairs: [[r, s, cost]] (welded), reference / source: {centre, radius,
//   extremities}} (lib/extremities.js: geodesic extremities, matched by relative distance and
//   direction from the centre). Plain JS (edge-length Dijkstra), a few ms on 15k vertices.
import { findExtremities, matchExtremities } from '../../lib/extremities.js';
import { MeshMorphError, unwrap } from '../../lib/errors.js';
import { meshInSlot } from './mesh.js';

function flatLandmarks(pairs) {
  if (pairs === undefined || pairs === null) return new Int32Array(0);
  if (!Array.isArray(pairs)) throw new MeshMorphError('InvalidArgument', 'landmarks must be an array of [reference, source] pairs');
  const flat = new Int32Array(2 * pairs.length);
  pairs.forEach((p, i) => {
    if (!Array.isArray(p) || p.length !== 2) throw new MeshMorphError('InvalidArgument', `landmark pair ${i} is not [reference, source]`);
    flat[2 * i] = p[0];
    flat[2 * i + 1] = p[1];
  });
  return flat;
}

// The info of a pose transfer result (poseTransfer's, or partTransfer's level1).
function poseInfo(r) {
  return {
    gammaDominance: r.gammaDominance, iterations: r.iterations, converged: r.converged,
    couplingIterations: r.couplingIterations, ms: r.ms, k: r.k, gamma: Array.from(r.gamma),
    foldRetry: r.foldRetry,
    flipRepair: r.flipRepair,
  };
}

export const ops = {
  transfer(ctx, options = {}, buffers = {}) {
    const { referenceSlot = 'reference', sourceSlot = 'main', landmarks, ...jobOptions } = options;
    const reference = meshInSlot(ctx, referenceSlot);
    const source = meshInSlot(ctx, sourceSlot);
    // The job's options go to the binding as given (read_options checks names and ranges).
    const r = unwrap(ctx.module.poseTransfer(reference.weldedPositions, reference.weldedIndices,
      source.weldedPositions, source.weldedIndices, flatLandmarks(landmarks), jobOptions,
      (stage, fraction) => ctx.progress(stage, fraction), buffers.cagePositions, buffers.cageIndices));
    return {
      buffers: {
        positions: Float32Array.from(r.positions),
        cagePositions: Float32Array.from(r.cagePositions),
        cageIndices: r.cageIndices,
      },
      info: poseInfo(r),
    };
  },

  partTransfer(ctx, options = {}) {
    const { referenceSlot = 'reference', sourceSlot = 'main', landmarks, parts = 'auto', partOptions = {}, ...jobOptions } = options;
    const reference = meshInSlot(ctx, referenceSlot);
    const source = meshInSlot(ctx, sourceSlot);
    const r = unwrap(ctx.module.partTransfer(reference.weldedPositions, reference.weldedIndices,
      source.weldedPositions, source.weldedIndices, flatLandmarks(landmarks), String(parts), jobOptions, partOptions,
      (stage, fraction) => ctx.progress(stage, fraction)));
    const partLabels = new Int32Array(source.weldedPositions.length / 3).fill(-1);
    // Depth first: a child comes after its parent, so the deepest part wins.
    r.parts.forEach((p, i) => { for (const v of p.sourceVertices ?? []) partLabels[v] = i; });
    return {
      buffers: { positions: Float32Array.from(r.positions), positionsLevel1: Float32Array.from(r.positionsLevel1), partLabels },
      info: {
        level1: poseInfo(r.level1),
        partsJson: r.partsJson,
        proposals: { tried: r.proposalsTried, kept: r.proposalKept, rounds: r.proposalRounds, landmarkErrorLevel1: r.landmarkErrorLevel1, landmarkError: r.landmarkError },
        parts: r.parts.map(({ sourceVertices, ...p }) => p),
        folds: r.folds,
        foldRetry: r.foldRetry,
        flipRepair: r.flipRepair,
        ms: r.ms,
      },
    };
  },

  suggestLandmarks(ctx, options = {}) {
    const { referenceSlot = 'reference', sourceSlot = 'main', count = 8, sameConnectivity = false } = options;
    const reference = meshInSlot(ctx, referenceSlot);
    const source = meshInSlot(ctx, sourceSlot);
    const r = findExtremities(reference.weldedPositions, reference.weldedIndices, { count });
    if (!ctx.progress('extremities', 0.5)) throw new MeshMorphError('Cancelled', 'cancelled');
    const s = sameConnectivity ? r : findExtremities(source.weldedPositions, source.weldedIndices, { count });
    const pairs = sameConnectivity
      ? r.extremities.map((e) => [e.vertex, e.vertex, 0])
      : matchExtremities(r, s).map((p) => [p.reference, p.source, p.cost]);
    return { buffers: {}, info: { pairs, reference: r, source: s } };
  },

  compare(ctx, options = {}, buffers = {}) {
    const b = meshInSlot(ctx, options.slotB || 'reference');
    const positionsA = buffers.positionsA ?? meshInSlot(ctx, options.slotA || 'main').weldedPositions;
    if (positionsA.length !== b.weldedPositions.length) {
      throw new MeshMorphError('InvalidArgument', `compare: ${positionsA.length / 3} and ${b.weldedPositions.length / 3} vertices (the meshes must share the vertex order)`);
    }
    const r = unwrap(ctx.module.transferMetrics(positionsA, b.weldedPositions, b.weldedIndices));
    const { ok, ...info } = r;
    return { buffers: {}, info };
  },
};
