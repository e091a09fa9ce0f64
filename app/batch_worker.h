// The batch worker (docs/batch.md): runs jobs of a batch manifest one at a time, keeping the
// precomputation of the last retarget source/target pairs so that every clip of a pair after the
// first only pays for its frames. `meshmorph batch --worker` runs run_batch_worker_loop in a
// child process of the batch (app/batch_run.h): one job per line of JSON on stdin, progress and
// results as lines of JSON on stdout.
//
// Reuse: RetargetJob::prepare fixes one clip, but its precomputation (harmonic maps of both
// characters, SVD, synthesis factorization: retarget/harmonic_retarget.h) depends only on the
// pair and the options. So the worker prepares a pair once — with the source's first clip,
// whatever the job's clip — and samples each job's clip through the session's source character
// and harmonic retargeter, writing the GLB exactly as RetargetJob::write_glb does
// (tests/batch_test.cpp checks the bytes against `meshmorph retarget --clip`). The LBS baseline
// keeps its state private, so it runs one RetargetJob per clip (its precomputation is cheap).
#pragma once

#include <list>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "app/batch_manifest.h"
#include "app/batch_state.h"
#include "common/progress.h"

namespace mm::app {

// The line that hands `job` to a worker, and its inverse.
std::string batch_job_message(const BatchJob& job);
Status parse_batch_job_message(const std::string& line, BatchJob* job);

// Flipped faces exactly as transfer_metrics counts them (a face whose normal opposes the
// area-weighted mean normal of its edge neighbours in the pose, while agreeing with it by more
// than 0.5 at rest), with the neighbours and the rest agreement computed once per target:
// transfer_metrics rebuilds its edge map on every call, which cost ~10× the retargeting of a frame.
class FlipCounter {
 public:
  FlipCounter(const Eigen::MatrixXd& rest, const Eigen::MatrixXi& F);
  int count(const Eigen::MatrixXd& V) const;

 private:
  Eigen::VectorXd agreement(const Eigen::MatrixXd& V) const;
  Eigen::MatrixXi F_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<char> agrees_at_rest_;
};

class BatchWorker {
 public:
  // reuse = false: every retarget job prepares its own session (to measure what reuse saves).
  explicit BatchWorker(bool reuse = true) : reuse_(reuse) {}
  ~BatchWorker();
  // Runs the job and writes its output atomically. The outcome's status is "ok" or "failed".
  BatchJobOutcome run(const BatchJob& job, const Progress& progress = {});

 private:
  struct RetargetContext;
  std::shared_ptr<RetargetContext> retarget_context(const BatchJob& job, const Progress& progress, BatchJobOutcome* o);
  Status run_retarget(const BatchJob& job, const Progress& progress, BatchJobOutcome* o);
  Status run_transfer(const BatchJob& job, const Progress& progress, BatchJobOutcome* o);
  Status run_edit(const BatchJob& job, const Progress& progress, BatchJobOutcome* o);
  Status run_merge(const BatchJob& job, const Progress& progress, BatchJobOutcome* o);

  bool reuse_;
  std::list<std::shared_ptr<RetargetContext>> contexts_;  // most recent first
};

// Reads job lines from in_fd until it closes; for each writes {"event":"progress",...} lines
// (at most ~10 per second) and one {"event":"done",...} line to out_fd. Returns the exit code.
// Natively only (the wasm build returns 2).
int run_batch_worker_loop(int in_fd, int out_fd, bool reuse);

// Writes all of `s` to a pipe or file descriptor, retrying short writes and EINTR (native only).
bool write_fd_all(int fd, const std::string& s);

// The "done" line ↔ the outcome it carries.
std::string batch_done_message(const BatchJobOutcome& o);
bool parse_batch_done_message(const nlohmann::json& j, BatchJobOutcome* o);

}  // namespace mm::app
