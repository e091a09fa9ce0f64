// Progress: the sink through which long computations report their stage and fraction,
// and through which a caller asks them to stop.
//
// A default-constructed Progress is a no-op that never cancels. A computation with several
// stages hands each stage a sub-range: `progress.sub(0.2, 0.7)` maps that stage's 0..1 onto
// 0.2..0.7 of the caller's bar. Cancellation is shared by all sub-ranges of one sink.
//
// Usage inside core:
//   if (!progress.update("factor", 0.5)) return cancelled_status("factor");
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>

#include "common/status.h"

namespace mm {

class Progress {
 public:
  // Called with the stage name and overall fraction in [0, 1]. Return false to request cancel.
  using Callback = std::function<bool(const std::string& stage, double fraction)>;

  Progress() = default;
  explicit Progress(Callback callback);

  // Reports `fraction` (0..1 within this sub-range) of `stage`. Returns false once cancel
  // was requested (by the callback now or earlier); the computation should then stop.
  // Threads may share a sink when its callback is thread-safe (the cancel flag is atomic).
  bool update(const std::string& stage, double fraction) const;

  // True once any update returned false.
  bool cancelled() const { return state_ && state_->cancelled.load(); }

  // A sink whose 0..1 maps to [begin, end] of this one (both in 0..1 of this sub-range).
  Progress sub(double begin, double end) const;
  // The same, and every update through it is reported as `stage` whatever the callee names it
  // (a library step such as a factorisation shows under its caller's name on the page's bar).
  Progress sub(double begin, double end, std::string stage) const;

 private:
  struct State {
    Callback callback;
    std::atomic<bool> cancelled{false};  // several threads may report (pose_transfer's cage thread)
  };
  std::shared_ptr<State> state_;
  double begin_ = 0.0;
  double end_ = 1.0;
  std::string stage_;  // non-empty: reported instead of the callee's stage name
};

// The Status a computation returns when its progress sink asked it to stop during `stage`.
Status cancelled_status(const std::string& stage);

}  // namespace mm
