// The moves of a running edit session (worker ops editDrag / editFinalize, worker/ops/edit.js):
// the handles' matrices step by step (undo / redo walk them), previews while a gizmo is dragged
// through a latest-only pump (lib/latest-only.js: one editDrag in flight, the newest matrices
// sent when its answer arrives), and settling — bring the mesh to some matrices and finalize it
// — when the user lets go, undoes, redoes or resets. Matrices are 16 numbers, column-major.
import { identity } from '../lib/edit-spec.js';
import { LatestOnly } from '../lib/latest-only.js';

const sameMatrix = (a, b) => a.length === b.length && a.every((v, i) => v === b[i]);
export const sameMatrices = (a, b) => Boolean(a && b) && a.length === b.length && a.every((m, i) => sameMatrix(m, b[i]));
const dragOptions = (matrices) => ({ transforms: matrices.map((matrix) => ({ matrix })) });

export class EditMoves {
  // client: the worker client (previews, without the busy overlay); runOp: the shell's (settling,
  // with progress and errors shown); mode() → 'keep' | 'scale'; finalizes() → false when the
  // session's method has no finalize step; onPositions(result) for every drag / finalize
  // result; onSettled(matrices) after a settle; onError(e) for failed previews.
  constructor({ client, runOp, mode, finalizes, onPositions, onSettled, onError }) {
    Object.assign(this, { client, runOp, mode, finalizes, onPositions, onSettled });
    this.reset(1);
    this.pump = new LatestOnly((matrices) => this.sendPreview(matrices), {
      onAnswer: (result, matrices) => {
        const started = performance.now();
        this.stats.answered += 1;
        this.lastDragged = matrices;
        onPositions(result);
        this.stats.last = performance.now();
        this.stats.applyMs += this.stats.last - started;
      },
      onError,
    });
  }

  // A new session with `handles` handles at rest.
  reset(handles) {
    this.history = [Array(handles).fill(identity)];
    this.at = 0;
    this.lastDragged = null; // the matrices of the last editDrag the worker answered
    this.finalized = 0;
    // sent / answered previews, first / last answer time, summed worker round trips and
    // geometry updates (ms)
    this.stats = { sent: 0, answered: 0, first: 0, last: 0, roundTripMs: 0, applyMs: 0 };
  }

  get current() {
    return this.history[this.at];
  }

  get canUndo() {
    return this.at > 0;
  }

  get canRedo() {
    return this.at < this.history.length - 1;
  }

  // The current matrices with handle h's replaced.
  with(h, matrix) {
    return this.current.map((m, i) => (i === h ? matrix : m));
  }

  sendPreview(matrices) {
    this.stats.sent += 1;
    const sentAt = performance.now();
    if (!this.stats.first) this.stats.first = sentAt;
    return this.client.run('editDrag', dragOptions(matrices)).promise.then((result) => {
      this.stats.roundTripMs += performance.now() - sentAt;
      return result;
    });
  }

  // While dragging: show these matrices as soon as the worker is free.
  preview(matrices) {
    this.pump.push(matrices);
  }

  // Brings the mesh to `matrices` and finalizes it; false when an op failed (already shown).
  async settle(matrices = this.current) {
    await this.pump.idle();
    if (!sameMatrices(this.lastDragged, matrices)) {
      const dragged = await this.runOp('Moving the handles', 'editDrag', dragOptions(matrices));
      if (!dragged) return false;
      this.lastDragged = matrices;
      if (!this.finalizes()) this.onPositions(dragged);
    }
    if (this.finalizes()) {
      const result = await this.runOp('Finalizing', 'editFinalize', { mode: this.mode() });
      if (!result) return false;
      this.onPositions(result);
    }
    this.finalized += 1;
    this.onSettled(matrices);
    return true;
  }

  // A new step (the user let go of the gizmo, or reset): drops the redo steps and settles.
  async commit(matrices) {
    if (sameMatrices(this.current, matrices) && this.finalized > 0) return true; // a click, no move
    this.history = this.history.slice(0, this.at + 1);
    this.history.push(matrices);
    this.at = this.history.length - 1;
    return this.settle(matrices);
  }

  // The steps of a session whose worker was replaced, in the new session: the same history and
  // place in it, settled there (nothing to settle at the first step, the rest shape).
  async restore(history, at) {
    this.history = history.map((matrices) => matrices.map((m) => m.slice()));
    this.at = Math.min(Math.max(at, 0), this.history.length - 1);
    return this.at === 0 ? true : this.settle(this.current);
  }

  // Undo (-1) / redo (+1): returns the matrices now current, or null when there is no such step.
  async step(delta) {
    const index = this.at + delta;
    if (index < 0 || index >= this.history.length) return null;
    this.at = index;
    await this.settle(this.current);
    return this.current;
  }
}
