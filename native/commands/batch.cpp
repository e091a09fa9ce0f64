// meshmorph batch — many jobs from one manifest, in worker processes, resumable, shardable
// (docs/batch.md; app/batch_manifest.h, app/batch_run.h, app/batch_worker.h).
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <iostream>

#include "app/batch_manifest.h"
#include "app/batch_run.h"
#include "app/batch_state.h"
#include "app/batch_worker.h"
#include "cli.h"
#include "io/asset.h"

namespace mm::cli {
namespace {

namespace fs = std::filesystem;

const char* kBatchUsage =
    "usage: meshmorph batch MANIFEST.json [--jobs N] [--shard i/n] [--summary S.json] [--force]\n"
    "                       [--dry-run] [--timeout SECONDS] [--no-reuse] [--quiet]\n"
    "       meshmorph batch MANIFEST.json --gather [--summary S.json]\n"
    "       meshmorph batch MANIFEST.json --slurm [--shards N] [--jobs K] [--summary S.json]\n"
    "  Runs the retarget, transfer, edit and merge jobs a manifest names (format: docs/batch.md,\n"
    "  app/batch_manifest.h) in N worker processes (default: the number of cores). A failing or\n"
    "  crashing job is reported and the others go on; outputs are written atomically; jobs whose\n"
    "  output is complete and up to date (same program version, inputs, options) are skipped, so\n"
    "  an interrupted batch resumes. Writes the summary S.json, the table S.txt and the state\n"
    "  S.state.json (default S: <manifest stem>.summary next to the manifest). Exit code 0 when\n"
    "  every job is ok, 1 when a job failed, 130 when interrupted.\n"
    "  --jobs N          worker processes\n"
    "  --shard i/n       run only shard i (0 <= i < n) of the job list: contiguous blocks, the\n"
    "                    same on every machine; writes S.shard-i-of-n.json\n"
    "  --gather          merge the shard summaries S.shard-*-of-n.json into S.json (and the state)\n"
    "  --slurm           write a Slurm job array (one task per shard, --shards N, default 4, with\n"
    "                    --jobs K cores each, default 2), its gather step and a submit script\n"
    "  --force           run every job, up to date or not\n"
    "  --dry-run         list the jobs and whether they would run; writes nothing\n"
    "  --timeout S       a job running longer than S seconds is killed and fails\n"
    "  --no-reuse        no shared precomputation between a retarget pair's clips (to measure it)\n"
    "  --quiet           no table on stdout, no per-job lines on stderr\n";

std::string self_exe() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<size_t>(n)) : std::string("meshmorph");
}

int run_worker(const Args& args) {
  const bool reuse = !args.has("no-reuse");
  args.get("worker");
  args.get("no-reuse");
  if (Status s = check_unused(args); !s.ok()) return report("batch", s);
  // The protocol owns the real stdout; anything else printed goes to stderr.
  const int proto = ::dup(STDOUT_FILENO);
  if (proto < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0)
    return report("batch", Status::error(StatusCode::IoError, "batch worker: cannot set up its output"));
  return app::run_batch_worker_loop(STDIN_FILENO, proto, reuse);
}

Status write_script(const std::string& path, const std::string& text) {
  Status s = io::write_file_atomic(path, std::vector<uint8_t>(text.begin(), text.end()));
  if (s.ok()) ::chmod(path.c_str(), 0755);
  return s;
}

int run_batch_command(const std::vector<std::string>& argv) {
  Args args;
  Status s = args.parse(argv, {"help", "worker", "force", "dry-run", "no-reuse", "quiet", "gather", "slurm"});
  if (!s.ok()) return report("batch", s);
  if (args.has("worker")) return run_worker(args);
  if (args.has("help") || args.positional().size() != 1) {
    std::cout << kBatchUsage;
    return args.has("help") ? 0 : 2;
  }
  auto flag = [&](const char* name) {
    if (!args.has(name)) return false;
    args.get(name);
    return true;
  };
  const std::string manifest_path = args.positional()[0];
  app::BatchRunOptions opt;
  opt.force = flag("force");
  opt.dry_run = flag("dry-run");
  opt.reuse = !flag("no-reuse");
  const bool quiet = flag("quiet"), gather = flag("gather"), slurm = flag("slurm");
  opt.workers = args.get_int("jobs", 0, &s);
  const int shards = args.get_int("shards", 4, &s);
  opt.timeout_s = args.get_double("timeout", 0, &s);
  if (!s.ok()) return report("batch", s);
  if (args.has("jobs") && (opt.workers < 1 || opt.workers > 1024))
    return report("batch", Status::error(StatusCode::InvalidArgument, "--jobs must be in 1..1024"));
  if (shards < 1 || shards > 100000)
    return report("batch", Status::error(StatusCode::InvalidArgument, "--shards must be in 1..100000"));
  if (opt.timeout_s < 0) return report("batch", Status::error(StatusCode::InvalidArgument, "--timeout must be >= 0"));
  if (args.has("shard") && !(s = app::parse_batch_shard(args.get("shard"), &opt.shard_index, &opt.shard_count)).ok())
    return report("batch", s);
  opt.summary_path = args.get("summary");
  if (int(gather) + int(slurm) + int(opt.shard_count > 0) > 1)
    return report("batch", Status::error(StatusCode::InvalidArgument, "--gather, --slurm and --shard exclude each other"));
  if (!(s = check_unused(args)).ok()) return report("batch", s);

  const app::BatchManifestResult mr = app::load_batch_manifest(manifest_path);
  if (!mr.status.ok()) return report("batch", mr.status);
  const app::BatchManifest& m = mr.manifest;
  const std::string summary = opt.summary_path.empty() ? m.summary_path : opt.summary_path;

  if (slurm) {
    std::error_code ec;
    const std::string abs_manifest = fs::absolute(manifest_path, ec).lexically_normal().string();
    const std::string abs_summary = fs::absolute(summary, ec).lexically_normal().string();
    const int n = std::max(1, std::min<int>(shards, static_cast<int>(m.jobs.size())));
    const int cpus = opt.workers > 0 ? opt.workers : 2;
    const app::SlurmScripts sc =
        app::batch_slurm_scripts(self_exe(), abs_manifest, abs_summary, fs::current_path(ec).string(), n, cpus);
    const std::string stem = abs_summary.substr(0, abs_summary.size() - 5);
    if (fs::path(stem).has_parent_path()) fs::create_directories(fs::path(stem).parent_path(), ec);
    for (const auto& [suffix, text] : {std::pair<std::string, std::string>{".slurm-array.sh", sc.array_script},
                                       {".slurm-gather.sh", sc.gather_script},
                                       {".slurm-submit.sh", sc.submit_script}})
      if (!(s = write_script(stem + suffix, text)).ok()) return report("batch", s);
    std::cout << "batch: " << m.jobs.size() << " jobs in " << n << " shards of ~" << (m.jobs.size() + n - 1) / n
              << " jobs, " << cpus << " cores each\n  wrote " << stem << ".slurm-array.sh (sbatch array, one task per shard)\n"
              << "  wrote " << stem << ".slurm-gather.sh (merges the shard summaries into " << abs_summary << ")\n"
              << "  wrote " << stem << ".slurm-submit.sh (submits both: the gather after the array, afterany)\n"
              << "  run: " << stem << ".slurm-submit.sh\n";
    return 0;
  }

  if (gather) {
    const app::BatchGatherResult g = app::gather_batch(m, summary);
    if (!g.status.ok()) return report("batch", g.status);
    const std::string json = app::batch_summary_json(g.summary), table = app::batch_summary_table(g.summary);
    if (!(s = io::write_file_atomic(summary, std::vector<uint8_t>(json.begin(), json.end()))).ok()) return report("batch", s);
    if (!(s = io::write_file_atomic(app::batch_table_path(summary), std::vector<uint8_t>(table.begin(), table.end()))).ok())
      return report("batch", s);
    if (!quiet) std::cout << table;
    std::cout << "batch: gathered " << g.shards_found << " of " << g.shards_expected << " shard(s) into " << summary << "\n";
    if (g.shards_found < g.shards_expected)
      std::cerr << "meshmorph batch: " << g.shards_expected - g.shards_found << " shard summary(ies) missing\n";
    return g.summary.count("failed") + g.summary.count("not-run") > 0 ? 1 : 0;
  }

  opt.worker_exe = self_exe();
  const bool bar = ::isatty(STDERR_FILENO);
  if (!quiet && !bar) opt.log = [](const std::string& line) { std::cerr << line << "\n"; };
  const app::BatchRunResult r = app::run_batch(m, opt, terminal_progress());
  if (bar) std::cerr << "\r\033[K";
  if (!quiet || opt.dry_run) std::cout << r.table;
  if (!opt.dry_run) std::cout << "batch: summary " << r.summary_path << "\n";
  if (!r.status.ok()) return report("batch", r.status);
  if (opt.dry_run) return 0;
  return r.summary.count("failed") + r.summary.count("not-run") > 0 ? 1 : 0;
}

}  // namespace

MM_COMMAND(batch, "run many jobs from a manifest in worker processes (resumable, shardable, Slurm)", run_batch_command);

}  // namespace mm::cli
