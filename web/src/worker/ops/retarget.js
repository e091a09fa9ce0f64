// Worker ops of the retarget module (bindings in wasm/bind_retarget.cpp, paper 002): precompute
// once, then frames in batches (each batch reports progress and can be cancelled), then export.
// The session stays in ctx.state.retarget until retargetDispose; playback in the page swaps the
// position attribute per frame (the UI issue), so frames come back as one Float32Array per batch.
import { MeshMorphError, unwrap } from '../../lib/errors.js';

function toBytes(value) {
  if (value instanceof Uint8Array) return value;
  if (value instanceof ArrayBuffer) return new Uint8Array(value);
  if (ArrayBuffer.isView(value)) return new Uint8Array(value.buffer, value.byteOffset, value.byteLength);
  throw new MeshMorphError('InvalidArgument', 'expected file bytes');
}

function session(ctx, id) {
  const s = ctx.state.retarget?.get(id);
  if (s === undefined) throw new MeshMorphError('InvalidArgument', `no retarget session ${id}; call retargetPrepare first`);
  return s;
}

export const ops = {
  // options: {sourceName, targetName, targetJointsJson? ('auto': fitted, as retargetJoints), jointMapJson?, ...any option of the
  //           retarget job's schema (optionSchema {job: 'retarget'}: clip, fps, first_frame, method, ...)}
  // buffers: {source: bytes, target: bytes}
  retargetPrepare(ctx, options = {}, buffers = {}) {
    const { sourceName, targetName, targetJointsJson, jointMapJson, ...jobOptions } = options;
    const r = unwrap(ctx.module.retargetPrepare(toBytes(buffers.source), sourceName || 'source.glb',
      toBytes(buffers.target), targetName || 'target.glb', targetJointsJson || '',
      jointMapJson || '', jobOptions, ctx.progress));
    if (!ctx.state.retarget) ctx.state.retarget = new Map();
    ctx.state.retarget.set(r.session, { frames: r.frames });
    return {
      info: { session: r.session, frames: r.frames, clip: r.clip, warnings: r.warnings },
      buffers: { times: r.times, targetPositions: r.targetPositions, targetIndices: r.targetIndices },
    };
  },
  // options: {session, first = 0, count = all remaining}
  retargetFrames(ctx, options = {}) {
    const s = session(ctx, options.session);
    const first = options.first ?? 0;
    const count = options.count ?? s.frames - first;
    const r = unwrap(ctx.module.retargetFrames(options.session, first, count, ctx.progress));
    return {
      info: { first, count: r.count, boneLengthError: r.boneLengthError, selfIntersections: r.selfIntersections },
      buffers: { positions: r.positions },
    };
  },
  // buffers: {positions: all frames, frame-major, as returned by retargetFrames}
  retargetExportGlb(ctx, options = {}, buffers = {}) {
    session(ctx, options.session);
    const r = unwrap(ctx.module.retargetExportGlb(options.session, buffers.positions));
    return { info: {}, buffers: { bytes: r.bytes } };
  },
  // Automatic joints for an unrigged target (issue 14; app/joints_job.h).
  // options: {sourceName, targetName, markersJson? ({"joint": [x, y, z]} pins), ...any option of
  //           the joints job's schema (optionSchema {job: 'joints'}: resolution, target_up, ...)}
  // buffers: {source: bytes, target: bytes}
  // → buffers {positions (#J·3), skeletonPositions (#N·3)} / info {json (give it to
  //   retargetPrepare as targetJointsJson), names, parents, skeletonParents, skipped, warnings,
  //   targetUp, limbEnds}
  retargetJoints(ctx, options = {}, buffers = {}) {
    const { sourceName, targetName, markersJson, ...jobOptions } = options;
    const r = unwrap(ctx.module.retargetJoints(toBytes(buffers.source), sourceName || 'source.glb',
      toBytes(buffers.target), targetName || 'target.glb', markersJson || '', jobOptions, ctx.progress));
    return {
      info: { json: r.json, names: r.names, parents: r.parents, skeletonParents: r.skeletonParents,
        skipped: r.skipped, warnings: r.warnings, targetUp: r.targetUp, limbEnds: r.limbEnds },
      buffers: { positions: r.positions, skeletonPositions: r.skeletonPositions },
    };
  },
  // The context graph of a session (harmonic with context_graph on): overlay sets.
  // options: {session} → info {sets: [{name, color, source (true: source units)}]}, buffers
  // {set0Positions, set0Lines, set1Positions, ...}
  retargetGraph(ctx, options = {}) {
    session(ctx, options.session);
    const r = unwrap(ctx.module.retargetGraph(options.session));
    const info = { sets: [] };
    const buffers = {};
    r.sets.forEach((set, i) => {
      info.sets.push({ name: set.name, color: set.color, source: !set.name.startsWith('target') });
      buffers[`set${i}Positions`] = set.positions;
      buffers[`set${i}Lines`] = set.lines;
    });
    return { info, buffers };
  },
  retargetDispose(ctx, options = {}) {
    ctx.state.retarget?.delete(options.session);
    return { info: { disposed: ctx.module.retargetDispose(options.session) }, buffers: {} };
  },
};
