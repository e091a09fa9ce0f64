// What a batch remembers and reports (docs/batch.md): job keys (SHA-256 of the program version,
// the job's kind, clip and options and the contents of its input files), the state file that
// lets a re-run skip jobs whose outputs are complete and up to date, the summary (JSON and a
// readable table), shard partitions and the gathering of shard summaries, and the Slurm scripts.
//
// Files next to the summary S.json: S.state.json (state), S.txt (table). A shard i of n writes
// S.shard-i-of-n.json (and its .state.json, .txt); gathering merges them into S.json.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/batch_manifest.h"
#include "common/status.h"

namespace mm::app {

// SHA-256 (FIPS 180-4), incremental.
class Sha256 {
 public:
  Sha256();
  void update(const void* data, size_t n);
  void update(const std::string& s) { update(s.data(), s.size()); }
  std::string hex();  // finishes; call once

 private:
  void block(const uint8_t* p);
  uint32_t h_[8];
  uint8_t buf_[64];
  size_t fill_ = 0;
  uint64_t bytes_ = 0;
};

// "meshmorph <version>": part of every job key, so a new program version re-runs every job.
std::string batch_program_version();

// SHA-256 of each input file's bytes (and of the buffers/images a .gltf names), cached by path.
class FileHashCache {
 public:
  // "" when the file cannot be read (the job then runs, and reports the error).
  const std::string& hash(const std::string& path);

 private:
  std::map<std::string, std::string> cache_;
};

// The job's key: program version, kind, clip, options and the hashes of its input files. ""
// when an input cannot be read (such a job is never up to date).
std::string batch_job_key(const BatchJob& job, FileHashCache* files);

// One row of the summary.
struct BatchJobOutcome {
  int index = 0;
  std::string id, label, kind, output;
  std::string status;          // "ok", "failed", "up-to-date", "not-run" (interrupted, or a missing shard)
  std::string message;         // failed: what went wrong ("[IoError] cannot open ...")
  nlohmann::json metrics = nlohmann::json::object();  // quality measures the job reports
  std::vector<std::string> warnings;
  // Timing (varies between runs; everything else in a row is reproducible).
  double time_ms = 0;          // the job in its worker (up-to-date: when it ran)
  double precompute_ms = 0;    // retarget: the shared precomputation this job paid for (0 = reused)
  bool reused = false;         // retarget: the precomputation was already in the worker
};

struct BatchSummary {
  std::string manifest, program;
  int shard_index = -1, shard_count = 0;  // -1/0: the whole manifest
  int jobs_total = 0;                     // jobs of the manifest (all shards)
  int workers = 0;
  double wall_ms = 0;
  std::vector<std::string> warnings;
  std::vector<BatchJobOutcome> jobs;      // by index
  int count(const std::string& status) const;
};

std::string batch_summary_json(const BatchSummary& s);
Status parse_batch_summary(const std::string& text, BatchSummary* s);
// Status, time, output and the main metrics of each job; totals at the end.
std::string batch_summary_table(const BatchSummary& s);

// The state: per job id, the key it ran with and the output it wrote (size and modification
// time, so that an output changed or removed since is rebuilt), with its metrics for the summary.
struct BatchStateEntry {
  std::string key, output;
  uint64_t size = 0;
  int64_t mtime_ns = 0;
  nlohmann::json metrics = nlohmann::json::object();
  std::vector<std::string> warnings;
  double time_ms = 0;
};
using BatchState = std::map<std::string, BatchStateEntry>;

// A missing file is an empty state; an unreadable or malformed one too (every job then runs),
// with a warning in *warning.
BatchState read_batch_state(const std::string& path, std::string* warning);
Status write_batch_state(const std::string& path, const BatchState& state);
// The entry for a job that just wrote `output` (its size and time now).
BatchStateEntry batch_state_entry(const BatchJobOutcome& o, const std::string& key);
// True when `e` was made with `key` and `output` still has the size and time it had then.
bool batch_output_current(const BatchStateEntry& e, const std::string& key, const std::string& output);

// File names next to a summary: "S.json" → "S.state.json", "S.txt", "S.shard-i-of-n.json".
std::string batch_state_path(const std::string& summary_path);
std::string batch_table_path(const std::string& summary_path);
std::string batch_shard_summary_path(const std::string& summary_path, int index, int count);

// Shard i of n (0 ≤ i < n): the contiguous block [i·N/n, (i+1)·N/n) of the job list, so each
// shard keeps whole runs of one source/target pair's clips (their precomputation is shared).
std::vector<int> batch_shard_jobs(int total, int index, int count);
// "i/n" → index, count. InvalidArgument unless 0 ≤ i < n.
Status parse_batch_shard(const std::string& text, int* index, int* count);

// Merges the shard summaries (and states) of `summary_path` into it: every job of the manifest
// must appear in exactly one shard; jobs of a missing shard are "not-run". *found: shards read.
struct BatchGatherResult {
  Status status;       // IoError/ParseError for unreadable summaries or inconsistent shard counts
  BatchSummary summary;
  int shards_found = 0, shards_expected = 0;
};
BatchGatherResult gather_batch(const BatchManifest& m, const std::string& summary_path);

// Slurm job-array script: one array task per shard, each running
// `meshmorph batch MANIFEST --shard $SLURM_ARRAY_TASK_ID/n --jobs $SLURM_CPUS_PER_TASK`; and the
// gather script, to be submitted with --dependency=afterany on the array.
struct SlurmScripts {
  std::string array_script, gather_script, submit_script;
};
SlurmScripts batch_slurm_scripts(const std::string& meshmorph, const std::string& manifest, const std::string& summary_path,
                                 const std::string& workdir, int shards, int cpus_per_task);

}  // namespace mm::app
