#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <thread>
#include <vector>

#include "common/portable_math.h"
#include "common/progress.h"
#include "common/status.h"
#include "common/threads.h"

namespace mm {

TEST(Status, DefaultIsOkAndNamesAreStable) {
  Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_STREQ(status_code_name(StatusCode::InvalidMesh), "InvalidMesh");
  EXPECT_STREQ(status_code_name(StatusCode::Cancelled), "Cancelled");
  const Status e = Status::error(StatusCode::ParseError, "bad");
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message, "bad");
}

TEST(Progress, NoopSinkNeverCancels) {
  Progress p;
  EXPECT_TRUE(p.update("x", 0.5));
  EXPECT_FALSE(p.cancelled());
}

TEST(Progress, SubRangesMapIntoParentAndShareCancel) {
  std::vector<double> seen;
  int calls = 0;
  Progress p([&](const std::string&, double f) {
    seen.push_back(f);
    return ++calls < 3;
  });
  const Progress a = p.sub(0.2, 0.6);
  const Progress b = a.sub(0.5, 1.0);  // 0.4 .. 0.6 overall
  EXPECT_TRUE(a.update("a", 0.5));
  EXPECT_TRUE(b.update("b", 0.5));
  EXPECT_FALSE(b.update("b", 1.0));  // third call: callback asks to cancel
  EXPECT_TRUE(p.cancelled());
  EXPECT_FALSE(a.update("a", 1.0));  // cancel is shared, callback not called again
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_NEAR(seen[0], 0.4, 1e-12);
  EXPECT_NEAR(seen[1], 0.5, 1e-12);
  EXPECT_NEAR(seen[2], 0.6, 1e-12);
  EXPECT_EQ(cancelled_status("factor").code, StatusCode::Cancelled);
}

TEST(Progress, SubRangeWithAStageReportsItsNameForEveryCallee) {
  std::vector<std::string> names;
  std::vector<double> seen;
  Progress p([&](const std::string& stage, double f) {
    names.push_back(stage);
    seen.push_back(f);
    return true;
  });
  const Progress named = p.sub(0.0, 0.5, "eigenbasis");
  named.update("factor: analysis", 0.5);
  named.sub(0.5, 1.0).update("factor", 1.0);  // a sub-range of it keeps the name
  p.update("factor", 1.0);                     // the parent is not renamed
  EXPECT_EQ(names, (std::vector<std::string>{"eigenbasis", "eigenbasis", "factor"}));
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_NEAR(seen[0], 0.25, 1e-12);
  EXPECT_NEAR(seen[1], 0.5, 1e-12);
}

TEST(Progress, FractionIsClamped) {
  double last = -1;
  Progress p([&](const std::string&, double f) {
    last = f;
    return true;
  });
  p.update("x", 7.0);
  EXPECT_EQ(last, 1.0);
  p.update("x", -1.0);
  EXPECT_EQ(last, 0.0);
}

// ---- tasks (common/threads.h). Also run in wasm: with -pthread (the JS tests' threaded module
// drives the same pool through the ops) and without (every task runs in wait()).

// Restores the default thread count when a test ends.
struct ThreadCount {
  explicit ThreadCount(int n) { set_max_threads(n); }
  ~ThreadCount() { set_max_threads(0); }
};

TEST(Tasks, OneThreadRunsTheWorkInWaitOnTheCallingThread) {
  ThreadCount one(1);
  const std::thread::id me = std::this_thread::get_id();
  std::thread::id ran;
  bool done = false;
  Task t([&] { ran = std::this_thread::get_id(), done = true; });
  EXPECT_FALSE(done);  // deferred: nothing runs before wait()
  t.wait();
  EXPECT_TRUE(done);
  EXPECT_EQ(ran, me);
  EXPECT_FALSE(t.valid());
}

TEST(Tasks, ManyMoreTasksThanThreadsAllRunOnceAndNestedWaitsDoNotDeadlock) {
  ThreadCount two(2);  // one pool thread at most: the nested tasks must be run by their owners
  constexpr int kOuter = 16, kInner = 8;
  std::vector<std::atomic<int>> runs(kOuter * (kInner + 1));
  for (auto& r : runs) r = 0;
  std::vector<Task> outer;
  for (int i = 0; i < kOuter; ++i) {
    outer.emplace_back([i, &runs] {
      std::vector<Task> inner;
      for (int j = 0; j < kInner; ++j) inner.emplace_back([i, j, &runs] { ++runs[i * (kInner + 1) + 1 + j]; });
      ++runs[i * (kInner + 1)];
      for (Task& t : inner) t.wait();
    });
  }
  for (Task& t : outer) t.wait();
  for (size_t k = 0; k < runs.size(); ++k) EXPECT_EQ(runs[k].load(), 1) << "piece " << k;
}

// The wasm test binary is linked without -pthread from the -pthread objects the threaded modules
// share (wasm/CMakeLists.txt): no thread can start there, so the core stays on one thread whatever
// is asked. Natively threads exist.
TEST(Tasks, ThreadsOnlyWhereTheLinkHasThem) {
#if defined(__EMSCRIPTEN__)
  EXPECT_FALSE(threads_supported());
  ThreadCount four(4);
  EXPECT_EQ(max_threads(), 1);
  std::atomic<int> ran{0};
  Task t([&] { ran += 1; });
  t.wait();
  EXPECT_EQ(ran.load(), 1);
#else
  EXPECT_TRUE(threads_supported());
  ThreadCount four(4);
  EXPECT_EQ(max_threads(), 4);
#endif
}

TEST(Tasks, WaitRethrowsTheWorksExceptionAndTheDestructorWaits) {
  ThreadCount two(2);
  Task bad([] { throw std::runtime_error("boom"); });
  EXPECT_THROW(bad.wait(), std::runtime_error);
  std::atomic<bool> finished{false};
  {
    Task slow([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = true;
    });
  }  // the destructor waits
  EXPECT_TRUE(finished.load());
  // wait_for: false while a pool thread still runs the work, true once done.
  std::atomic<bool> started{false}, release{false};
  struct Release {  // a failed assertion below must not leave the destructor waiting forever
    std::atomic<bool>& flag;
    ~Release() { flag = true; }
  };
  Task held([&] {
    started = true;
    while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  const Release on_exit{release};  // destroyed before `held`
  if (threads_supported()) {  // (without threads the work runs in wait_for below, after the release)
    for (int i = 0; i < 10000 && !started.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(started.load()) << "no pool thread took the task within 10 s";
    EXPECT_FALSE(held.wait_for(std::chrono::milliseconds(5)));
  }
  release = true;
  EXPECT_TRUE(held.wait_for(std::chrono::milliseconds(5000)));
}

TEST(Tasks, AStoppableTaskIsStoppedByItsOwnersEarlyReturn) {
  // Work that runs until it is told to stop (bounded at 10 s so a broken stop fails, not hangs).
  auto until_stopped = [](std::atomic<int>* reports, std::atomic<bool>* stopped) {
    return [reports, stopped](const Progress& watch) {
      const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (std::chrono::steady_clock::now() < end) {
        if (!watch.update("spin", 0.5)) {
          *stopped = true;
          return;
        }
        ++*reports;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    };
  };
  for (int threads : {1, 2}) {
    ThreadCount count(threads);
    std::atomic<int> reports{0}, recorded{0};
    std::atomic<bool> stopped{false};
    const auto t0 = std::chrono::steady_clock::now();
    {
      StoppableTask task(until_stopped(&reports, &stopped), [&](const std::string& stage, double f) {
        EXPECT_EQ(stage, "spin");
        EXPECT_EQ(f, 0.5);
        ++recorded;
        return false;  // the recorder cannot stop the work: only the owner can
      });
      if (threads_supported() && threads > 1)
        for (int i = 0; i < 10000 && reports.load() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      EXPECT_FALSE(task.stop_requested());
    }  // an early return: the destructor stops the work, then waits for it
    EXPECT_TRUE(stopped.load()) << threads << " threads";
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
    if (threads_supported() && threads > 1) EXPECT_GE(reports.load(), 3);
    else EXPECT_EQ(reports.load(), 0);  // run in the destructor, already stopped
    EXPECT_EQ(recorded.load(), reports.load() + 1);  // every report, the refused one too
    // Assigning over a running task stops the old one; wait() lets the new one finish.
    std::atomic<int> reports2{0};
    std::atomic<bool> stopped2{false}, ran{false};
    StoppableTask a(until_stopped(&reports2, &stopped2));
    a = StoppableTask([&ran](const Progress& watch) { ran = watch.update("once", 1.0); });
    EXPECT_TRUE(stopped2.load());
    a.wait();
    EXPECT_TRUE(ran.load());
  }
}

TEST(Tasks, TwoHalvesGiveTheSameSumAsOneLoop) {
  std::vector<double> x(100000);
  for (size_t i = 0; i < x.size(); ++i) x[i] = 1.0 / static_cast<double>(i + 1);
  double one = 0, lo = 0, hi = 0;
  one = std::accumulate(x.begin(), x.begin() + 50000, 0.0) + std::accumulate(x.begin() + 50000, x.end(), 0.0);
  {
    ThreadCount two(2);
    Task upper([&] { hi = std::accumulate(x.begin() + 50000, x.end(), 0.0); });
    lo = std::accumulate(x.begin(), x.begin() + 50000, 0.0);
    upper.wait();
  }
  EXPECT_EQ(lo + hi, one);
}

TEST(Tasks, ParallelBlocksCoverTheRangeOnceInContiguousBlocks) {
  for (int threads : {1, 2, 4}) {
    ThreadCount count(threads);
    for (long n : {0L, 1L, 7L, 1000L, 1001L}) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(n));
      for (auto& h : hits) h = 0;
      std::atomic<int> calls{0};
      parallel_blocks(n, 100, [&](long begin, long end) {
        ++calls;
        EXPECT_LT(begin, end);
        for (long i = begin; i < end; ++i) ++hits[static_cast<size_t>(i)];
      });
      for (long i = 0; i < n; ++i) EXPECT_EQ(hits[static_cast<size_t>(i)].load(), 1) << "n " << n << " item " << i;
      // At most one block per thread, and none smaller than asked unless the range is.
      EXPECT_LE(calls.load(), std::max(1, std::min<int>(threads, static_cast<int>(std::max(1L, n / 100)))));
    }
  }
}

}  // namespace mm

// portable_asin: within one unit in the last place of the C library's asin (glibc natively; in
// wasm musl, whose asin is the same algorithm: equal bits), exact at the ends, NaN outside
// [−1, 1]; and the same bits in every build: a hash of its results over 200,000 arguments in
// all of its branches is a constant here, checked by the native and the wasm test runs alike.
TEST(PortableMath, AsinWithinAnUlpAndTheSameBitsInEveryBuild) {
  uint64_t state = 12345, hash = 1469598103934665603ull;
  double worst_ulp = 0;
  auto check = [&](double x) {
    const double a = mm::portable_asin(x), b = std::asin(x);
    int64_t ia, ib;
    std::memcpy(&ia, &a, 8);
    std::memcpy(&ib, &b, 8);
    worst_ulp = std::max(worst_ulp, std::fabs(static_cast<double>(ia - ib)));
    for (int k = 0; k < 8; ++k) hash = (hash ^ ((static_cast<uint64_t>(ia) >> (8 * k)) & 0xff)) * 1099511628211ull;
  };
  for (int i = 0; i < 40000; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double u = static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
    check(u);                 // [0, 1): all branches
    check(-u);
    check(0.5 * u);           // below one half: the branch the loops use
    check(0.97 + 0.03 * u);   // the branch above 0.975
    check(std::ldexp(u, -30));  // below 2⁻²⁶
  }
  EXPECT_LE(worst_ulp, 1.0);
#ifdef __EMSCRIPTEN__
  EXPECT_EQ(worst_ulp, 0.0) << "musl's asin is fdlibm's: the same bits";
#endif
  EXPECT_EQ(hash, 0x6745c4be69119f3eull) << std::hex << hash;
  EXPECT_EQ(mm::portable_asin(1.0), std::asin(1.0));
  EXPECT_EQ(mm::portable_asin(-1.0), std::asin(-1.0));
  EXPECT_EQ(mm::portable_asin(0.0), 0.0);
  EXPECT_TRUE(std::signbit(mm::portable_asin(-0.0)));
  EXPECT_TRUE(std::isnan(mm::portable_asin(1.0000000000000002)));
  EXPECT_TRUE(std::isnan(mm::portable_asin(std::nan(""))));
  // The branch-free form equals the full function below one half.
  for (double x : {0.0, 1e-300, 1e-9, 0.1, 0.25, 0.4999999999999999})
    EXPECT_EQ(mm::asin_below_half(x), mm::portable_asin(x)) << x;
}
