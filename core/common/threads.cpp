#include "common/threads.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__EMSCRIPTEN__) && MM_HAS_THREADS
#include <emscripten/threading.h>
#endif

namespace mm {
namespace {

std::atomic<int> g_override{0};

int default_threads() {
#if !MM_HAS_THREADS
  return 1;
#else
#if !defined(__EMSCRIPTEN__)
  if (const char* e = std::getenv("MM_THREADS")) {
    char* end = nullptr;
    const long n = std::strtol(e, &end, 10);
    if (end != e && *end == '\0' && n >= 1 && n <= 1024) return static_cast<int>(n);
  }
#endif
  const unsigned hw = std::thread::hardware_concurrency();
  return hw >= 1 ? static_cast<int>(hw) : 1;
#endif
}

}  // namespace

bool threads_supported() {
#if !MM_HAS_THREADS
  return false;
#elif defined(__EMSCRIPTEN__)
  // The -pthread link's library_pthread.js says yes; the stub library of a link without -pthread
  // (the single-threaded modules, built from the same objects) says no.
  static const bool supported = emscripten_has_threading_support() != 0;
  return supported;
#else
  return true;
#endif
}

int max_threads() {
  if (!threads_supported()) return 1;  // whatever was asked
  static const int d = default_threads();
  const int o = g_override.load();
  return o >= 1 ? o : d;
}

void set_max_threads(int n) { g_override.store(n >= 1 ? n : 0); }

// ---- tasks

struct Task::State {
  enum Phase { Queued, Running, Done };
  std::function<void()> work;
  Phase phase = Queued;
  std::exception_ptr error;
};

namespace {

// One pool per process, never destroyed (its threads wait on the condition variable until the
// process ends). All task phases are guarded by its one mutex: tasks are few and coarse.
struct Pool {
  std::mutex mutex;
  std::condition_variable work_ready;  // a task was queued
  std::condition_variable task_done;   // some task finished
  std::deque<std::shared_ptr<Task::State>> queue;
  int threads = 0;  // started (never stopped)
  int busy = 0;     // of which running a task: at most max_threads() − 1, whatever was started

  static Pool& get() {
    static Pool* pool = new Pool;  // leaked on purpose: see above
    return *pool;
  }

  // Runs a task the caller has just marked Running (outside the lock).
  void run(const std::shared_ptr<Task::State>& t) {
    try {
      t->work();
    } catch (...) {
      t->error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex);
    t->phase = Task::State::Done;
    t->work = nullptr;
    task_done.notify_all();
  }

#if MM_HAS_THREADS
  void loop() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      work_ready.wait(lock, [this] { return !queue.empty() && busy < std::min(max_threads() - 1, kMaxPoolThreads); });
      std::shared_ptr<Task::State> t = std::move(queue.front());
      queue.pop_front();
      if (t->phase != Task::State::Queued) continue;  // its owner took it back
      t->phase = Task::State::Running;
      ++busy;
      lock.unlock();
      run(t);
      lock.lock();
      --busy;
      if (!queue.empty()) work_ready.notify_one();
    }
  }

  // Called with the mutex held, by the first task's owner: all kMaxPoolThreads threads at once
  // (idle ones only wait; `busy` keeps the running ones within max_threads() − 1). Starting them
  // together from the first owner matters in wasm: a pthread started from another pthread is
  // spawned by the main thread's event loop, which never turns while an op blocks on its tasks.
  void grow_locked() {
    while (threads < kMaxPoolThreads) {
      std::thread(&Pool::loop, this).detach();
      ++threads;
    }
  }
#endif
};

}  // namespace

Task::Task(std::function<void()> work) : state_(std::make_shared<State>()) {
  state_->work = std::move(work);
#if MM_HAS_THREADS
  if (max_threads() > 1) {
    Pool& pool = Pool::get();
    std::lock_guard<std::mutex> lock(pool.mutex);
    pool.grow_locked();
    pool.queue.push_back(state_);
    pool.work_ready.notify_one();
  }
#endif
}

Task& Task::operator=(Task&& other) noexcept {
  if (this != &other) {
    finish_quietly();
    state_ = std::move(other.state_);
  }
  return *this;
}

Task::~Task() { finish_quietly(); }

bool Task::wait_for(std::chrono::milliseconds timeout) {
  if (!state_) return true;
  Pool& pool = Pool::get();
  std::unique_lock<std::mutex> lock(pool.mutex);
  if (state_->phase == State::Queued) {
    // No thread has started it: run it here (a queued copy is skipped by the pool).
    state_->phase = State::Running;
    lock.unlock();
    pool.run(state_);
    lock.lock();
  }
  // While a pool thread runs it, this thread helps with other queued tasks (it would only wait
  // otherwise; e.g. the transfer's caller runs the cage thread's second half of the mean-value
  // rows), then waits.
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (state_->phase != State::Done) {
    std::shared_ptr<State> other;
    while (!pool.queue.empty() && !other) {
      other = std::move(pool.queue.front());
      pool.queue.pop_front();
      if (other->phase != State::Queued) other.reset();
    }
    if (other) {
      other->phase = State::Running;
      lock.unlock();
      pool.run(other);
      lock.lock();
      continue;
    }
    if (pool.task_done.wait_until(lock, deadline) == std::cv_status::timeout && state_->phase != State::Done) return false;
  }
  std::exception_ptr error = state_->error;
  state_.reset();
  if (error) std::rethrow_exception(error);
  return true;
}

void Task::wait() {
  while (!wait_for(std::chrono::milliseconds(1000))) {
  }
}

void Task::finish_quietly() noexcept {
  try {
    wait();
  } catch (...) {
  }
}

StoppableTask::StoppableTask(std::function<void(const Progress&)> work, Progress::Callback record)
    : stop_(std::make_shared<std::atomic<bool>>(false)) {
  const std::shared_ptr<std::atomic<bool>> stop = stop_;
  const Progress watch([stop, record = std::move(record)](const std::string& stage, double f) {
    if (record) record(stage, f);
    return !stop->load();
  });
  task_ = Task([watch, work = std::move(work)] { work(watch); });
}

StoppableTask& StoppableTask::operator=(StoppableTask&& other) noexcept {
  if (this != &other) {
    request_stop();
    task_ = std::move(other.task_);  // waits for the old work
    stop_ = std::move(other.stop_);
  }
  return *this;
}

void parallel_blocks(long n, long min_block, const std::function<void(long, long)>& fn) {
  if (n <= 0) return;
  const long most = std::max(1L, n / std::max(1L, min_block));
  const long blocks = std::min<long>({static_cast<long>(std::max(1, max_threads())), static_cast<long>(kMaxPoolThreads) + 1, most});
  if (blocks <= 1) {
    fn(0, n);
    return;
  }
  std::vector<Task> tasks;
  tasks.reserve(static_cast<size_t>(blocks - 1));
  for (long b = 1; b < blocks; ++b) tasks.emplace_back([&fn, b, blocks, n] { fn(n * b / blocks, n * (b + 1) / blocks); });
  fn(0, n / blocks);  // (an exception here waits for the tasks in their destructors)
  for (Task& t : tasks) t.wait();
}

}  // namespace mm
