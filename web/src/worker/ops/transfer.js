// Worker ops of the transfer module (bindings in wasm/bind_transfer.cpp): spectral pose transfer
// (paper 000) between two loaded meshes, and the comparison metrics. Listed in
// worker/ops/index.js like every ops file.
//
// transfer: options {referenceSlot = 'reference', sourceSlot = 'main', landmarks?: [[r, s], ...],
//   method?: 'yin'|'kovnatsky'|'levy', lambda1?, lambda2?, num_low_frequencies?, num_eigenpairs?,
//   cage_vertices?, cage_resolution?, max_iterations?, placement?: 'reference'|'source'}
//   → buffers {positions: Float32Array (welded #V·3 of the source), cagePositions, cageIndices}
//     info {gammaDominance, iterations, converged, couplingIterations, ms, k, gamma: number[]}
//   Progress messages carry the core's stages (eigenbasis, coupled bases, cage: …,
//   mean-value coordinates, optimisation); returning false from ctx.progress cancels.
// compare: options {slotA = 'main', slotB = 'reference'} (same vertex order)
//   → info {vertexErrorMean, vertexErrorMax, laplacianChange, edgeDistortionMean,
//           edgeDistortionMax, flippedFaces}
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

export const ops = {
  transfer(ctx, options = {}) {
    const reference = meshInSlot(ctx, options.referenceSlot || 'reference');
    const source = meshInSlot(ctx, options.sourceSlot || 'main');
    const r = unwrap(ctx.module.poseTransfer(reference.weldedPositions, reference.weldedIndices,
      source.weldedPositions, source.weldedIndices, flatLandmarks(options.landmarks), {
        method: options.method, lambda1: options.lambda1, lambda2: options.lambda2,
        num_low_frequencies: options.num_low_frequencies, num_eigenpairs: options.num_eigenpairs,
        cage_vertices: options.cage_vertices, cage_resolution: options.cage_resolution,
        max_iterations: options.max_iterations, placement: options.placement,
      }, (stage, fraction) => ctx.progress(stage, fraction)));
    return {
      buffers: {
        positions: Float32Array.from(r.positions),
        cagePositions: Float32Array.from(r.cagePositions),
        cageIndices: r.cageIndices,
      },
      info: {
        gammaDominance: r.gammaDominance, iterations: r.iterations, converged: r.converged,
        couplingIterations: r.couplingIterations, ms: r.ms, k: r.k, gamma: Array.from(r.gamma),
      },
    };
  },

  compare(ctx, options = {}) {
    const a = meshInSlot(ctx, options.slotA || 'main');
    const b = meshInSlot(ctx, options.slotB || 'reference');
    const r = unwrap(ctx.module.transferMetrics(a.weldedPositions, b.weldedPositions, b.weldedIndices));
    const { ok, ...info } = r;
    return { buffers: {}, info };
  },
};
