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
  // options: {sourceName, targetName, targetJointsJson?, jointMapJson?, ...any option of the
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
    return { info: { first, count: r.count }, buffers: { positions: r.positions } };
  },
  // buffers: {positions: all frames, frame-major, as returned by retargetFrames}
  retargetExportGlb(ctx, options = {}, buffers = {}) {
    session(ctx, options.session);
    const r = unwrap(ctx.module.retargetExportGlb(options.session, buffers.positions));
    return { info: {}, buffers: { bytes: r.bytes } };
  },
  retargetDispose(ctx, options = {}) {
    ctx.state.retarget?.delete(options.session);
    return { info: { disposed: ctx.module.retargetDispose(options.session) }, buffers: {} };
  },
};
