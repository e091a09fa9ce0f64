// Runs a retargeting in the worker without blocking the page: retargetPrepare, then the frames
// in growing batches (the first ones small, so the first frame plays soon), each handed to the
// page as it arrives. Latest only: start() while a run is going cancels the request in flight
// (cooperative cancel, lib/client.js) and forgets that run; its session is disposed. Nothing
// here touches the DOM; `run` and `cancel` are the client's (tests pass fakes).
//
// Events (onEvent(type, detail)), all for the current run only:
//   'progress' {phase: 'prepare' | 'frames', stage, fraction}  fraction of the phase, 0…1
//   'prepared' {info, buffers}     retargetPrepare's answer (session, frames, times, target)
//   'frames'   {first, count, positions, boneLengthError, selfIntersections} (per frame, the core's checks)
//   'done'     {session, frames}
//   'error'    {error}             a failure (MeshMorphError); the run is over
//   'stopped'  {}                  stop() ended it

export const defaultBatchSizes = [2, 6, 12, 24];

export class RetargetRunner {
  // run(op, options, buffers, {onProgress}) → {id, promise}; cancel(id).
  constructor({ run, cancel, onEvent = () => {}, batchSizes = defaultBatchSizes }) {
    this.run = run;
    this.cancel = cancel;
    this.onEvent = onEvent;
    this.batchSizes = batchSizes;
    this.generation = 0;
    this.inFlight = null;  // {id, generation}
    this.session = null;   // the current run's session, once prepared
    this.running = false;
    this.runs = 0;
  }

  // request: {options (retargetPrepare's), buffers() → fresh {source, target} bytes (they are
  // transferred to the worker)}. Resolves when this run ends (done, failed or superseded).
  async start(request) {
    this.generation += 1;
    const generation = this.generation;
    this.runs += 1;
    this.cancelInFlight();
    this.disposeSession();
    this.running = true;
    const current = () => generation === this.generation;
    try {
      const prepared = await this.call(generation, 'retargetPrepare', request.options, request.buffers(), 'prepare');
      if (!current()) {
        this.dispose(prepared.info.session);
        return;
      }
      this.session = prepared.info.session;
      this.onEvent('prepared', prepared);
      const total = prepared.info.frames;
      let next = 0;
      let batch = 0;
      while (next < total) {
        const count = Math.min(this.batchSizes[Math.min(batch, this.batchSizes.length - 1)], total - next);
        const first = next;
        const r = await this.call(generation, 'retargetFrames', { session: this.session, first, count }, {}, 'frames',
          (f) => (first + f * count) / total);
        if (!current()) return;
        this.onEvent('frames', {
          first, count: r.info.count, positions: r.buffers.positions,
          boneLengthError: r.info.boneLengthError, selfIntersections: r.info.selfIntersections,
        });
        next += r.info.count;
        batch += 1;
        if (r.info.count === 0) break;
      }
      this.running = false;
      this.onEvent('done', { session: this.session, frames: total });
    } catch (error) {
      if (!current()) return; // superseded: its cancel was on purpose
      this.running = false;
      this.onEvent('error', { error });
    }
  }

  // Ends the current run (its request is cancelled; frames already handed out stay valid).
  stop() {
    if (!this.running) return false;
    this.generation += 1;
    this.running = false;
    this.cancelInFlight();
    this.onEvent('stopped', {});
    return true;
  }

  call(generation, op, options, buffers, phase, overall = (f) => f) {
    const { id, promise } = this.run(op, options, buffers, {
      onProgress: (stage, fraction) => {
        if (generation === this.generation) this.onEvent('progress', { phase, stage, fraction: overall(fraction) });
      },
    });
    this.inFlight = { id, generation };
    return promise.finally(() => {
      if (this.inFlight?.id === id) this.inFlight = null;
    });
  }

  cancelInFlight() {
    if (!this.inFlight) return;
    this.cancel(this.inFlight.id);
    this.inFlight = null;
  }

  disposeSession() {
    if (this.session != null) this.dispose(this.session);
    this.session = null;
  }

  dispose(session) {
    // Fire and forget: the worker runs it after whatever it is doing.
    this.run('retargetDispose', { session }, {}, {}).promise.catch(() => {});
  }
}
