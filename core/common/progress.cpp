#include "common/progress.h"

#include <algorithm>

namespace mm {

Progress::Progress(Callback callback) : state_(std::make_shared<State>()) {
  state_->callback = std::move(callback);
}

bool Progress::update(const std::string& stage, double fraction) const {
  if (!state_) return true;
  if (state_->cancelled.load()) return false;
  if (state_->callback) {
    const double f = begin_ + (end_ - begin_) * std::clamp(fraction, 0.0, 1.0);
    if (!state_->callback(stage_.empty() ? stage : stage_, f)) state_->cancelled.store(true);
  }
  return !state_->cancelled.load();
}

Progress Progress::sub(double begin, double end) const {
  Progress p = *this;
  p.begin_ = begin_ + (end_ - begin_) * begin;
  p.end_ = begin_ + (end_ - begin_) * end;
  return p;
}

Progress Progress::sub(double begin, double end, std::string stage) const {
  Progress p = sub(begin, end);
  p.stage_ = std::move(stage);
  return p;
}

Status cancelled_status(const std::string& stage) {
  return Status::error(StatusCode::Cancelled, "cancelled during " + stage);
}

}  // namespace mm
