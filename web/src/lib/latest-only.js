// A request pump that keeps pace with a slower consumer (the worker): at most one request is in
// flight; values pushed meanwhile replace each other, and when the answer arrives the latest one
// is sent. A fast gizmo drag thus never builds a queue of stale requests, and the last position
// the user reached is always sent.
export class LatestOnly {
  // send(value) → Promise of the answer; onAnswer(answer, value) is called for every answer,
  // onError(error, value) for every failure (the pump keeps working).
  constructor(send, { onAnswer = () => {}, onError = () => {} } = {}) {
    this.sendFn = send;
    this.onAnswer = onAnswer;
    this.onError = onError;
    this.inFlight = null;  // Promise of the current request, or null
    this.pending = null;   // {value} waiting for the current request to finish
    this.sent = 0;
    this.answered = 0;
    this.idleWaiters = [];
  }

  push(value) {
    if (this.inFlight) this.pending = { value };
    else this.start(value);
  }

  start(value) {
    this.sent += 1;
    this.inFlight = Promise.resolve()
      .then(() => this.sendFn(value))
      .then((answer) => { this.answered += 1; this.onAnswer(answer, value); },
        (error) => this.onError(error, value))
      .finally(() => {
        this.inFlight = null;
        const next = this.pending;
        this.pending = null;
        if (next) this.start(next.value);
        else for (const resolve of this.idleWaiters.splice(0)) resolve();
      });
  }

  // Drops a value that has not been sent yet (e.g. the drag was cancelled).
  dropPending() {
    this.pending = null;
  }

  // Resolves when nothing is in flight or pending.
  idle() {
    if (!this.inFlight && !this.pending) return Promise.resolve();
    return new Promise((resolve) => this.idleWaiters.push(resolve));
  }
}
