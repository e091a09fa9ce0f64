// How many threads the core may keep busy at once, and the tasks it hands to other threads.
//
// The core overlaps independent stages (the transfer's cage and mean-value coordinates beside the
// eigenbases, the editor's Poisson factor beside the Eq. 7 system) and splits a few loops (the
// Eq. 7 columns and the supernodal factor's subtrees in two; mean-value rows, the retargeter's
// per-frame product and inside tests in blocks, parallel_blocks). Each
// piece does the same arithmetic whichever thread runs it, so results are bit-identical whatever
// the thread count.
//
// Where threads exist: natively, and in the wasm modules linked with -pthread (the page's module
// when crossOriginIsolated). The wasm objects are compiled with -pthread once (MM_WASM_THREADS) and
// linked twice: the single-threaded modules link them without shared memory, where pthreads are
// stubs, so threads_supported() is false and max_threads() is 1 there. A wasm build compiled
// without -pthread compiles the threaded paths out (MM_HAS_THREADS = 0). Only the calling thread reports progress: in
// wasm the progress sink calls JavaScript, which lives on that thread alone.
//
// Tasks run on a small pool of long-lived threads, not on a thread per task: in wasm a finished
// pthread's Worker only returns to Emscripten's pool when the calling thread's event loop turns,
// which never happens inside one computation, so threads started per task would exhaust the pool
// within one op and the next start would wait forever.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>

#include "common/progress.h"

#if !defined(__EMSCRIPTEN__) || defined(__EMSCRIPTEN_PTHREADS__)
#define MM_HAS_THREADS 1
#else
#define MM_HAS_THREADS 0
#endif

namespace mm {

// False where no thread can be started: a wasm module linked without -pthread (whatever its
// objects were compiled with), or a build without threads.
bool threads_supported();

// Default: MM_THREADS from the environment when it is a positive integer (natively), else the
// hardware's concurrency (navigator.hardwareConcurrency / node's CPU count in wasm), at least 1.
// Always 1 without threads (threads_supported() false).
int max_threads();
// n ≥ 1 overrides the default (the bench's --threads, the wasm binding setMaxThreads); n ≤ 0
// goes back to it. Not meant to be changed while a computation runs.
void set_max_threads(int n);

// Most pool threads ever started (the wasm build's PTHREAD_POOL_SIZE must be at least this): the
// core never has more than three pieces of work in flight besides the caller's own.
constexpr int kMaxPoolThreads = 3;

// A piece of work handed to the pool. It runs on a pool thread if one takes it before the owner
// waits; otherwise the owner runs it itself in wait() (so a busy or empty pool, or a task started
// from a pool thread, never deadlocks). While a pool thread runs it, the waiting owner runs other
// queued tasks. With max_threads() = 1 it is always run in wait(). Exceptions from the work are
// rethrown by wait(). The destructor waits (without rethrowing).
class Task {
 public:
  Task() = default;
  explicit Task(std::function<void()> work);
  Task(Task&&) noexcept = default;
  Task& operator=(Task&& other) noexcept;
  ~Task();

  bool valid() const { return state_ != nullptr; }
  // Waits until the work is done (running it here if no thread has started it).
  void wait();
  // Like wait(), but returns false after `timeout` if a pool thread is still running the work.
  bool wait_for(std::chrono::milliseconds timeout);

  struct State;

 private:
  void finish_quietly() noexcept;
  std::shared_ptr<State> state_;
};

// A Task whose owner may return before it needs the result (an error, a cancel): the work gets a
// Progress `watch` whose update() returns false once the owner asked it to stop, and the
// destructor asks it to stop before it waits, so an early return never waits for work whose
// result it drops. `record`, if given, is called with every report of the work (from the thread
// running it: it must be thread-safe); the watch never calls the owner's own sink, which in wasm
// lives on the calling thread alone.
class StoppableTask {
 public:
  StoppableTask() = default;
  explicit StoppableTask(std::function<void(const Progress& watch)> work, Progress::Callback record = {});
  StoppableTask(StoppableTask&&) noexcept = default;
  StoppableTask& operator=(StoppableTask&& other) noexcept;
  ~StoppableTask() { request_stop(); }  // then task_'s destructor waits

  bool valid() const { return task_.valid(); }
  // The work's watch returns false from its next update on.
  void request_stop() {
    if (stop_) stop_->store(true);
  }
  bool stop_requested() const { return stop_ && stop_->load(); }
  void wait() { task_.wait(); }
  bool wait_for(std::chrono::milliseconds timeout) { return task_.wait_for(timeout); }

 private:
  std::shared_ptr<std::atomic<bool>> stop_;
  Task task_;  // after stop_: destroyed (waited for) first
};

// Splits [0, n) into up to min(max_threads(), kMaxPoolThreads + 1) contiguous blocks of at least
// `min_block` items and runs fn(begin, end) on each: the first block on the calling thread, the
// others as tasks; returns when all are done (rethrowing the first block's exception, else a
// task's). fn must write disjoint outputs and compute each item the same way whatever its block,
// so the results do not depend on the thread count. Only the first block (begin == 0) runs on the
// calling thread, so only it may report progress (mean_value_coordinates does so).
void parallel_blocks(long n, long min_block, const std::function<void(long begin, long end)>& fn);

}  // namespace mm
