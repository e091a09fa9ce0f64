#include "app/batch_run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#ifndef __EMSCRIPTEN__
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#if defined(__linux__)
#include <sys/prctl.h>
#endif
#endif

#include "app/batch_worker.h"
#include "io/asset.h"
#include "io/json_text.h"

namespace mm::app {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double ms_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

BatchJobOutcome outcome_of(const BatchJob& job) {
  BatchJobOutcome o;
  o.index = job.index;
  o.id = job.id;
  o.label = job.label;
  o.kind = batch_kind_name(job.kind);
  o.output = job.output;
  return o;
}

// Temporary files io::write_file_atomic leaves when its process is killed mid-write
// ("<output>.mm-tmp-<pid>"): removed before the job runs again.
void remove_stale_temporaries(const std::vector<const BatchJob*>& jobs) {
  std::map<fs::path, std::set<std::string>> by_dir;
  for (const BatchJob* j : jobs) {
    const fs::path p(j->output);
    by_dir[p.has_parent_path() ? p.parent_path() : fs::path(".")].insert(p.filename().string() + ".mm-tmp-");
  }
  for (const auto& [dir, prefixes] : by_dir) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      const size_t at = name.find(".mm-tmp-");
      if (at != std::string::npos && prefixes.count(name.substr(0, at + 8))) fs::remove(e.path(), ec);
    }
  }
}

}  // namespace

#ifndef __EMSCRIPTEN__

namespace {

std::string seconds_text(double ms) {
  char buf[32];
  std::snprintf(buf, sizeof buf, ms < 10000 ? "%.2f s" : "%.0f s", ms / 1000);
  return buf;
}

volatile std::sig_atomic_t g_interrupted = 0;
void on_interrupt(int) { g_interrupted = 1; }

struct Worker {
  pid_t pid = -1;
  int in = -1, out = -1, err = -1;  // our ends of its stdin, stdout, stderr
  std::string out_buffer, err_tail;
  int job = -1;                     // manifest index of the job it runs, -1 = idle
  double fraction = 0;
  Clock::time_point started;
  std::string group;                // the group of its last job (what it has prepared)
  bool timed_out = false;
  bool alive() const { return pid > 0; }
};

void close_fd(int* fd) {
  if (*fd >= 0) ::close(*fd);
  *fd = -1;
}

// Starts `exe batch --worker` with pipes on its stdin, stdout and stderr.
Status spawn(Worker* w, const std::string& exe, bool reuse) {
  int pin[2], pout[2], perr[2];
  if (::pipe(pin) != 0) return Status::error(StatusCode::IoError, std::string("pipe: ") + std::strerror(errno));
  if (::pipe(pout) != 0) {
    ::close(pin[0]), ::close(pin[1]);
    return Status::error(StatusCode::IoError, std::string("pipe: ") + std::strerror(errno));
  }
  if (::pipe(perr) != 0) {
    ::close(pin[0]), ::close(pin[1]), ::close(pout[0]), ::close(pout[1]);
    return Status::error(StatusCode::IoError, std::string("pipe: ") + std::strerror(errno));
  }
  for (int fd : {pin[1], pout[0], perr[0]}) ::fcntl(fd, F_SETFD, FD_CLOEXEC);  // ours only
  std::vector<std::string> args = {exe, "batch", "--worker"};
  if (!reuse) args.push_back("--no-reuse");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    for (int fd : {pin[0], pin[1], pout[0], pout[1], perr[0], perr[1]}) ::close(fd);
    return Status::error(StatusCode::IoError, std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {  // the child: only async-signal-safe calls until exec
    const int from[3] = {pin[0], pout[1], perr[1]};
    for (int t = 0; t < 3; ++t) {
      if (from[t] == t) ::fcntl(t, F_SETFD, 0);
      else ::dup2(from[t], t);
    }
    ::setpgid(0, 0);  // a Ctrl-C reaches the batch, which stops its workers itself
#if defined(__linux__)
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // and a killed batch takes its workers along
    if (::getppid() != parent) ::_exit(1);
#endif
    ::signal(SIGPIPE, SIG_DFL);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    for (int fd = 3; fd < 1024; ++fd) ::close(fd);
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(pin[0]), ::close(pout[1]), ::close(perr[1]);
  w->pid = pid;
  w->in = pin[1];
  w->out = pout[0];
  w->err = perr[0];
  ::fcntl(w->out, F_SETFL, ::fcntl(w->out, F_GETFL) | O_NONBLOCK);
  ::fcntl(w->err, F_SETFL, ::fcntl(w->err, F_GETFL) | O_NONBLOCK);
  w->out_buffer.clear();
  w->err_tail.clear();
  w->job = -1;
  w->group.clear();
  w->timed_out = false;
  return Status::success();
}

// Reads what is there; false at end of file (or an error).
bool drain(int fd, std::string* into, size_t keep_tail) {
  char chunk[8192];
  for (;;) {
    const ssize_t r = ::read(fd, chunk, sizeof chunk);
    if (r > 0) {
      into->append(chunk, static_cast<size_t>(r));
      if (keep_tail && into->size() > keep_tail) into->erase(0, into->size() - keep_tail);
      continue;
    }
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
    if (r < 0 && errno == EINTR) continue;
    return false;
  }
}

std::string last_line(const std::string& text) {
  std::string t = text;
  while (!t.empty() && (t.back() == '\n' || t.back() == '\r')) t.pop_back();
  const size_t nl = t.rfind('\n');
  return io::quote_input(nl == std::string::npos ? t : t.substr(nl + 1), 300);
}

std::string death_text(int wstatus) {
  if (WIFSIGNALED(wstatus)) {
    const int sig = WTERMSIG(wstatus);
    const char* name = ::strsignal(sig);
    return "killed by signal " + std::to_string(sig) + (name ? std::string(" (") + name + ")" : "");
  }
  if (WIFEXITED(wstatus)) return "exited with code " + std::to_string(WEXITSTATUS(wstatus));
  return "stopped";
}

// The scheduler: jobs grouped by what a worker can share between them.
class Queue {
 public:
  void add(const BatchJob& job) {
    const std::string g = job.group.empty() ? "#" + std::to_string(job.index) : job.group;
    if (!groups_.count(g)) order_.push_back(g);
    groups_[g].push_back(job.index);
    ++size_;
  }
  size_t size() const { return size_; }
  // The next job for a worker that prepared `mine`, while the others hold `held`; its group in *group.
  int pick(const std::string& mine, const std::multiset<std::string>& held, std::string* group) {
    auto take = [&](const std::string& g) {
      std::deque<int>& q = groups_[g];
      const int j = q.front();
      q.pop_front();
      --size_;
      *group = g;
      return j;
    };
    if (!mine.empty() && groups_.count(mine) && !groups_[mine].empty()) return take(mine);
    const std::string* best = nullptr;
    for (int pass = 0; pass < 2 && !best; ++pass) {  // first the groups no one holds, then any
      size_t most = 0;
      for (const std::string& g : order_) {
        const size_t n = groups_[g].size();
        if (n > most && (pass == 1 || !held.count(g))) most = n, best = &g;
      }
    }
    return best ? take(*best) : -1;
  }

 private:
  std::map<std::string, std::deque<int>> groups_;
  std::vector<std::string> order_;
  size_t size_ = 0;
};

}  // namespace

#endif  // __EMSCRIPTEN__

BatchRunResult run_batch(const BatchManifest& m, const BatchRunOptions& opt, const Progress& progress) {
  BatchRunResult r;
  const auto t0 = Clock::now();
  const bool sharded = opt.shard_count > 0;
  const int total = static_cast<int>(m.jobs.size());
  const std::string base = opt.summary_path.empty() ? m.summary_path : opt.summary_path;
  r.summary_path = sharded ? batch_shard_summary_path(base, opt.shard_index, opt.shard_count) : base;
  const std::string state_path = batch_state_path(r.summary_path);

  BatchSummary& S = r.summary;
  S.manifest = m.path;
  S.program = batch_program_version();
  S.shard_index = sharded ? opt.shard_index : -1;
  S.shard_count = sharded ? opt.shard_count : 0;
  S.jobs_total = total;
  S.warnings = m.warnings;

  std::vector<int> mine;
  if (sharded) mine = batch_shard_jobs(total, opt.shard_index, opt.shard_count);
  else
    for (int k = 0; k < total; ++k) mine.push_back(k);

  std::string warning;
  BatchState state = read_batch_state(state_path, &warning);
  if (!warning.empty()) S.warnings.push_back(warning);
  FileHashCache hashes;
  std::map<int, BatchJobOutcome> outcomes;
  std::map<int, std::string> keys;
  std::vector<const BatchJob*> to_run;
  for (int k : mine) {
    const BatchJob& job = m.jobs[static_cast<size_t>(k)];
    BatchJobOutcome o = outcome_of(job);
    if (!job.preflight.ok()) {
      o.status = "failed";
      o.message = std::string("[") + status_code_name(job.preflight.code) + "] " + job.preflight.message;
      outcomes[k] = o;
      continue;
    }
    keys[k] = batch_job_key(job, &hashes);
    const auto it = state.find(job.id);
    if (!opt.force && it != state.end() && batch_output_current(it->second, keys[k], job.output)) {
      o.status = "up-to-date";
      o.metrics = it->second.metrics;
      o.warnings = it->second.warnings;
      o.time_ms = it->second.time_ms;
      outcomes[k] = o;
      continue;
    }
    o.status = opt.dry_run ? "to-run" : "not-run";
    outcomes[k] = o;
    to_run.push_back(&job);
  }

  auto finish = [&]() {
    S.jobs.clear();
    for (auto& [k, o] : outcomes) S.jobs.push_back(o);
    S.wall_ms = ms_between(t0, Clock::now());
    r.table = batch_summary_table(S);
  };
  if (opt.dry_run) {
    finish();
    return r;
  }

  // Folders: the summary's and every output's.
  std::error_code ec;
  const fs::path sp(r.summary_path);
  if (sp.has_parent_path()) fs::create_directories(sp.parent_path(), ec);
  std::vector<const BatchJob*> runnable;
  for (const BatchJob* j : to_run) {
    const fs::path op(j->output);
    // create_directories returns false when the folder already exists, which happens when another
    // process (a Slurm task of the same array) made it between the two calls: the folder being
    // there afterwards is what counts.
    if (op.has_parent_path()) {
      std::error_code mk;
      fs::create_directories(op.parent_path(), mk);
      if (!fs::is_directory(op.parent_path(), ec)) {
        BatchJobOutcome& o = outcomes[j->index];
        o.status = "failed";
        o.message = "[IoError] cannot create the folder '" + io::quote_input(op.parent_path().string(), 200) + "'" +
                    (mk ? " (" + mk.message() + ")" : std::string());
        continue;
      }
    }
    runnable.push_back(j);
  }
  remove_stale_temporaries(runnable);

  auto save_state = [&]() {
    if (Status s = write_batch_state(state_path, state); !s.ok() && r.status.ok()) r.status = s;
  };

#ifdef __EMSCRIPTEN__
  if (!runnable.empty()) r.status = Status::error(StatusCode::Unsupported, "batch runs need worker processes (native only)");
#else
  if (!runnable.empty()) {
    if (::access(opt.worker_exe.c_str(), X_OK) != 0) {
      r.status = Status::error(StatusCode::IoError, "cannot run the worker '" + io::quote_input(opt.worker_exe, 200) + "'");
      finish();
      return r;
    }
    int n_workers = opt.workers > 0 ? opt.workers : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    n_workers = std::min<int>(n_workers, static_cast<int>(runnable.size()));
    S.workers = n_workers;
    Queue queue;
    for (const BatchJob* j : runnable) queue.add(*j);
    std::vector<Worker> workers(static_cast<size_t>(n_workers));

    g_interrupted = 0;
    struct sigaction act {}, old_int {}, old_term {}, old_pipe {};
    act.sa_handler = on_interrupt;
    sigemptyset(&act.sa_mask);
    ::sigaction(SIGINT, &act, &old_int);
    ::sigaction(SIGTERM, &act, &old_term);
    struct sigaction ign {};
    ign.sa_handler = SIG_IGN;
    sigemptyset(&ign.sa_mask);
    ::sigaction(SIGPIPE, &ign, &old_pipe);

    const int to_do = static_cast<int>(runnable.size());
    int done = 0, failed = 0;
    bool stop = false;
    auto record = [&](BatchJobOutcome o) {
      const int k = o.index;
      const BatchJob& job = m.jobs[static_cast<size_t>(k)];
      o.id = job.id;
      o.label = job.label;
      o.kind = batch_kind_name(job.kind);
      o.output = job.output;
      ++done;
      if (o.status == "ok") {
        state[job.id] = batch_state_entry(o, keys[k]);
      } else {
        ++failed;
        state.erase(job.id);
      }
      save_state();
      if (opt.log) {
        char head[64];
        std::snprintf(head, sizeof head, "[%d/%d] %s %s ", done, to_do, o.status == "ok" ? "ok" : "FAILED",
                      seconds_text(o.time_ms).c_str());
        opt.log(head + o.id + (o.status == "ok" ? "" : ": " + o.message));
      }
      outcomes[k] = std::move(o);
    };
    auto report = [&]() {
      double f = done;
      for (const Worker& w : workers)
        if (w.job >= 0) f += w.fraction;
      const std::string stage = "batch " + std::to_string(done) + "/" + std::to_string(to_do) +
                                (failed ? ", " + std::to_string(failed) + " failed" : "");
      if (!progress.update(stage, to_do ? f / to_do : 1.0)) stop = true;
    };
    // A worker's end: its job (if any) fails, with what it said last on stderr.
    auto bury = [&](Worker& w) {
      int wstatus = 0;
      while (::waitpid(w.pid, &wstatus, 0) < 0 && errno == EINTR) {
      }
      drain(w.err, &w.err_tail, 4000);
      if (w.job >= 0) {
        const BatchJob& job = m.jobs[static_cast<size_t>(w.job)];
        BatchJobOutcome o = outcome_of(job);
        o.time_ms = ms_between(w.started, Clock::now());
        if (stop || g_interrupted) {
          o.status = "not-run";
          o.message = "interrupted";
          outcomes[w.job] = o;
        } else {
          o.status = "failed";
          o.message = w.timed_out ? "[Timeout] killed after " + seconds_text(opt.timeout_s * 1000) + " (--timeout)"
                                  : "[Crash] the worker " + death_text(wstatus) + " while running this job";
          const std::string said = last_line(w.err_tail);
          if (!said.empty() && !w.timed_out) o.message += "; it said: " + said;
          record(o);
        }
        std::error_code e2;
        fs::remove(job.output + ".mm-tmp-" + std::to_string(static_cast<long long>(w.pid)), e2);
      }
      close_fd(&w.in), close_fd(&w.out), close_fd(&w.err);
      w.pid = -1;
      w.job = -1;
    };

    Status spawn_error;
    while (true) {
      if (g_interrupted) stop = true;
      if (stop) break;
      // Hand out jobs; start workers as long as there are jobs for them.
      for (Worker& w : workers) {
        if (w.job >= 0 || queue.size() == 0) continue;
        if (!w.alive()) {
          if (Status s = spawn(&w, opt.worker_exe, opt.reuse); !s.ok()) {
            spawn_error = s;
            continue;
          }
        }
        std::multiset<std::string> held;  // what the other workers have prepared
        for (const Worker& o : workers)
          if (&o != &w && o.alive() && !o.group.empty()) held.insert(o.group);
        const int j = queue.pick(w.group, held, &w.group);
        w.job = j;
        w.fraction = 0;
        w.started = Clock::now();
        if (!write_fd_all(w.in, batch_job_message(m.jobs[static_cast<size_t>(j)]))) ::kill(w.pid, SIGKILL);  // reported at EOF
      }
      // Idle workers with nothing left to do: close their input, they exit.
      if (queue.size() == 0)
        for (Worker& w : workers)
          if (w.alive() && w.job < 0 && w.in >= 0) close_fd(&w.in);
      bool busy = false, any_alive = false;
      for (const Worker& w : workers) busy |= w.job >= 0, any_alive |= w.alive();
      if (!busy && queue.size() == 0 && !any_alive) break;
      if (!busy && !any_alive && queue.size() > 0) {  // no worker could start
        r.status = spawn_error.ok() ? Status::error(StatusCode::IoError, "no worker could start") : spawn_error;
        break;
      }
      std::vector<pollfd> fds;
      std::vector<std::pair<Worker*, bool>> who;  // worker, is stdout
      for (Worker& w : workers) {
        if (!w.alive()) continue;
        if (w.out >= 0) fds.push_back({w.out, POLLIN, 0}), who.push_back({&w, true});
        if (w.err >= 0) fds.push_back({w.err, POLLIN, 0}), who.push_back({&w, false});
      }
      const int pr = ::poll(fds.data(), fds.size(), 100);
      if (pr < 0 && errno != EINTR) break;
      for (size_t i = 0; pr > 0 && i < fds.size(); ++i) {
        if (!fds[i].revents) continue;
        Worker& w = *who[i].first;
        if (!w.alive()) continue;
        if (!who[i].second) {
          if (!drain(w.err, &w.err_tail, 4000)) close_fd(&w.err);
          continue;
        }
        const bool open = drain(w.out, &w.out_buffer, 0);
        size_t nl;
        while ((nl = w.out_buffer.find('\n')) != std::string::npos) {
          const std::string line = w.out_buffer.substr(0, nl);
          w.out_buffer.erase(0, nl + 1);
          const Json j = Json::parse(line, nullptr, false);
          if (!j.is_object() || !j.contains("index") || !j["index"].is_number_integer() || j["index"].get<int>() != w.job)
            continue;
          const std::string event = j.value("event", "");
          if (event == "progress") {
            w.fraction = std::clamp(j.value("f", 0.0), 0.0, 1.0);
          } else if (event == "done") {
            BatchJobOutcome o = outcome_of(m.jobs[static_cast<size_t>(w.job)]);
            if (!parse_batch_done_message(j, &o)) {
              o.status = "failed";
              o.message = "[Crash] the worker sent a malformed result";
            }
            w.job = -1;
            record(o);
          }
        }
        if (!open) bury(w);
      }
      if (opt.timeout_s > 0)
        for (Worker& w : workers)
          if (w.alive() && w.job >= 0 && !w.timed_out && ms_between(w.started, Clock::now()) > opt.timeout_s * 1000) {
            w.timed_out = true;
            ::kill(w.pid, SIGKILL);
          }
      report();
    }
    // Stop what still runs (interrupted, or cancelled through the progress sink).
    for (Worker& w : workers) {
      if (!w.alive()) continue;
      close_fd(&w.in);
      if (w.job >= 0) ::kill(w.pid, SIGKILL);
      bury(w);
    }
    ::sigaction(SIGINT, &old_int, nullptr);
    ::sigaction(SIGTERM, &old_term, nullptr);
    ::sigaction(SIGPIPE, &old_pipe, nullptr);
    if (stop && r.status.ok()) r.status = Status::error(StatusCode::Cancelled, "the batch was interrupted; run it again to resume");
    for (auto& [k, o] : outcomes)
      if (o.status == "not-run" && o.message.empty()) o.message = "interrupted";
  }
#endif
  save_state();
  finish();
  const std::string json = batch_summary_json(S);
  if (Status s = io::write_file_atomic(r.summary_path, std::vector<uint8_t>(json.begin(), json.end())); !s.ok() && r.status.ok())
    r.status = s;
  if (Status s = io::write_file_atomic(batch_table_path(r.summary_path), std::vector<uint8_t>(r.table.begin(), r.table.end()));
      !s.ok() && r.status.ok())
    r.status = s;
  return r;
}

}  // namespace mm::app
