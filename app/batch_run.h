// Running a batch (docs/batch.md): the jobs of a manifest (or of one shard of it) that are not
// up to date run in N worker processes — fork/exec of the meshmorph binary as
// `meshmorph batch --worker` (app/batch_worker.h) — so that a job that crashes or is killed
// fails alone. A free worker gets the next job of the source/target pair it already prepared
// when there is one, else the pair with the most jobs left that no other worker holds.
// After every finished job the state file is rewritten (atomically), so an interrupted batch
// resumes where it stopped; at the end the summary (JSON) and the table are written.
// Natively only: the wasm build returns Unsupported.
#pragma once

#include <functional>
#include <string>

#include "app/batch_manifest.h"
#include "app/batch_state.h"
#include "common/progress.h"

namespace mm::app {

struct BatchRunOptions {
  std::string worker_exe;        // the meshmorph binary, started as `worker_exe batch --worker`
  int workers = 0;               // worker processes; 0 = the number of cores
  int shard_index = -1;          // with shard_count > 0: run shard i of n only
  int shard_count = 0;
  std::string summary_path;      // "" = the manifest's (a shard writes S.shard-i-of-n.json)
  bool force = false;            // run every job, whatever the state says
  bool reuse = true;             // workers share a retarget pair's precomputation between its clips
  bool dry_run = false;          // only say which jobs would run (nothing is written)
  double timeout_s = 0;          // a job running longer is killed and fails; 0 = no limit
  // One line per finished job ("[3/12] ok 1.2 s out/...") — for logs when there is no bar.
  std::function<void(const std::string&)> log;
};

struct BatchRunResult {
  Status status;             // manifest-level problems (unwritable summary, no worker could start);
                             // failed jobs are in the summary, not here. Cancelled when interrupted.
  BatchSummary summary;
  std::string summary_path;  // where it was written
  std::string table;         // batch_summary_table(summary)
};

// Progress: one bar for the whole batch ("batch 12/228, 1 failed"); returning false cancels.
// SIGINT/SIGTERM during the run stop it the same way (workers are stopped, finished jobs kept).
BatchRunResult run_batch(const BatchManifest& manifest, const BatchRunOptions& options, const Progress& progress = {});

}  // namespace mm::app
