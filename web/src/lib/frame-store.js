// The Retarget job's frames on the page thread: frames arrive from the worker in batches, in
// any order (a batch is [first, first + count)); playback needs "which frames are here", the
// buffered ranges for the timeline, and target positions at a clip time, interpolated between
// the two frames around it when both are here.
//
// times: clip time of every frame (seconds, ascending; retargetPrepare's `times`).
// vertexCount: #V of the target surface; a frame is #V·3 floats.

export class FrameStore {
  constructor(times, vertexCount) {
    this.times = Float64Array.from(times);
    this.vertexCount = vertexCount;
    this.count = this.times.length;
    this.frames = new Array(this.count).fill(null); // Float32Array views, or null
    this.received = 0;
  }

  // positions: count·#V·3 floats, frame-major (retargetFrames' `positions`).
  add(first, count, positions) {
    const n = this.vertexCount * 3;
    if (positions.length !== count * n) throw new Error(`a batch of ${count} frames needs ${count * n} floats, got ${positions.length}`);
    if (first < 0 || first + count > this.count) throw new Error(`frames [${first}, ${first + count}) outside [0, ${this.count})`);
    for (let k = 0; k < count; ++k) {
      if (!this.frames[first + k]) this.received += 1;
      this.frames[first + k] = positions.subarray(k * n, (k + 1) * n);
    }
  }

  has(k) { return k >= 0 && k < this.count && this.frames[k] !== null; }

  get complete() { return this.received === this.count; }

  // Frames 0 … contiguous()-1 are all here: the playable prefix.
  contiguous() {
    let k = 0;
    while (k < this.count && this.frames[k]) k += 1;
    return k;
  }

  // [[first, end), …] of received frames, ascending.
  ranges() {
    const out = [];
    let start = -1;
    for (let k = 0; k <= this.count; ++k) {
      const here = k < this.count && this.frames[k];
      if (here && start < 0) start = k;
      if (!here && start >= 0) {
        out.push([start, k]);
        start = -1;
      }
    }
    return out;
  }

  // The frame index at or before clip time t (clamped to [0, count-1]).
  frameAt(t) {
    const { times } = this;
    if (!(t > times[0])) return 0;
    if (t >= times[this.count - 1]) return this.count - 1;
    let lo = 0;
    let hi = this.count - 1;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid;
      else hi = mid;
    }
    return lo;
  }

  // Positions at clip time t into `out` (Float32Array #V·3): linear between frames k and k+1
  // when both are here; else the nearest received frame at or before t (or after it, when
  // none is before). Returns {frame, exact} (exact: frame k itself is here) or null when no
  // frame has arrived.
  positionsAt(t, out) {
    if (this.received === 0) return null;
    const k = this.frameAt(t);
    const a = this.frames[k];
    const b = k + 1 < this.count ? this.frames[k + 1] : null;
    if (a && b) {
      const span = this.times[k + 1] - this.times[k];
      const s = span > 0 ? Math.min(1, Math.max(0, (t - this.times[k]) / span)) : 0;
      for (let i = 0; i < out.length; ++i) out[i] = a[i] + s * (b[i] - a[i]);
      return { frame: k, exact: true };
    }
    if (a) {
      out.set(a);
      return { frame: k, exact: true };
    }
    let j = k - 1;
    while (j >= 0 && !this.frames[j]) j -= 1;
    if (j < 0) {
      j = k + 1;
      while (j < this.count && !this.frames[j]) j += 1;
    }
    out.set(this.frames[j]);
    return { frame: j, exact: false };
  }

  // All received frames, frame-major, when the prefix [0, n) is complete (export takes the
  // first n frames); null otherwise.
  prefixPositions(n = this.contiguous()) {
    if (n === 0 || this.contiguous() < n) return null;
    const size = this.vertexCount * 3;
    const out = new Float32Array(n * size);
    for (let k = 0; k < n; ++k) out.set(this.frames[k], k * size);
    return out;
  }
}

// The playback clock: time in [start, end] of the clip, advanced by wall-clock seconds × speed
// while playing, looping at `loopEnd` (the end of the playable prefix while frames are still
// arriving, the clip's end once all are here).
export class PlaybackClock {
  constructor({ start = 0, end = 0 } = {}) {
    this.start = start;
    this.end = end;
    this.time = start;
    this.playing = false;
    this.speed = 1;
  }

  setRange(start, end) {
    this.start = start;
    this.end = Math.max(start, end);
    this.time = Math.min(Math.max(this.time, this.start), this.end);
  }

  // Advances by dt seconds (wall clock); returns the new time. loopEnd ≤ end: where to wrap.
  tick(dt, loopEnd = this.end) {
    if (!this.playing) return this.time;
    const stop = Math.min(Math.max(loopEnd, this.start), this.end);
    const span = stop - this.start;
    if (!(span > 0)) {
      this.time = this.start;
      return this.time;
    }
    let t = this.time + dt * this.speed;
    if (t > stop) t = this.start + ((t - this.start) % span);
    if (t < this.start) t = stop - ((this.start - t) % span);
    this.time = t;
    return t;
  }

  seek(t) {
    this.time = Math.min(Math.max(t, this.start), this.end);
    return this.time;
  }
}
