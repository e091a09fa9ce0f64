// Worker ops for the end-to-end checks of the page's recovery (tests/e2e/run.mjs): they put
// the worker into the states the client must recover from, which real inputs reach only after
// minutes (a 1M-vertex eigenbasis fills the 4 GB wasm heap after about 3.5 minutes of
// factorization). No panel calls them.
//   debugExhaustMemory {}  → info {allocatedMB}: allocates wasm heap in 64 MB blocks until
//     malloc fails and keeps it, so the next op that needs memory fails with OutOfMemory
//     (the bindings' guard, wasm/guard.h) exactly as when a huge input fills the heap.
//   debugCrash {}          → the worker dies with an uncaught error right after answering.
export const ops = {
  debugExhaustMemory(ctx) {
    const block = 64 << 20;
    ctx.state.debugBlocks ??= [];
    for (let size = block; size >= 1 << 20;) {
      const pointer = ctx.module._malloc(size);
      if (pointer) ctx.state.debugBlocks.push(pointer);
      else size >>= 1;
    }
    return { buffers: {}, info: { allocatedMB: ctx.module.HEAP8.length / 2 ** 20 } };
  },

  debugCrash() {
    setTimeout(() => { throw new Error('debugCrash: the worker dies (test)'); }, 0);
    return { buffers: {}, info: {} };
  },
};
