#include "app/batch_worker.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#ifndef __EMSCRIPTEN__
#include <unistd.h>

#include <cerrno>
#endif

#include <Eigen/Geometry>

#include "app/edit_job.h"
#include "app/json_options.h"
#include "app/merge_job.h"
#include "app/retarget_job.h"
#include "app/transfer_job.h"
#include "character/prop_tracks.h"
#include "io/asset.h"
#include "io/gltf_animation.h"
#include "io/json_text.h"
#include "metrics/retarget_metrics.h"
#include "metrics/transfer_metrics.h"

namespace mm::app {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

Status read_text(const std::string& path, std::string* out) {
  std::vector<uint8_t> bytes;
  Status s = io::read_file(path, &bytes);
  if (s.ok()) out->assign(bytes.begin(), bytes.end());
  return s;
}

std::string file_of(const BatchJob& job, const std::string& role) {
  const auto it = job.files.find(role);
  return it == job.files.end() ? std::string() : it->second;
}

template <class O>
Status options_of(const BatchJob& job, const OptionSchema<O>& schema, O* o) {
  const Json j = Json::parse(job.options_json.empty() ? "{}" : job.options_json, nullptr, false);
  if (j.is_discarded()) return Status::error(StatusCode::ParseError, "job options are not valid JSON");
  return set_options_from_json(j, schema, o, "options");
}
}  // namespace

// ---- messages

std::string batch_job_message(const BatchJob& job) {
  Json j;
  j["index"] = job.index;
  j["id"] = job.id;
  j["kind"] = batch_kind_name(job.kind);
  j["label"] = job.label;
  j["files"] = job.files;
  j["clip"] = job.clip;
  j["options"] = Json::parse(job.options_json.empty() ? "{}" : job.options_json, nullptr, false);
  j["output"] = job.output;
  j["group"] = job.group;
  return j.dump() + "\n";
}

Status parse_batch_job_message(const std::string& line, BatchJob* job) {
  const Json j = Json::parse(line, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Status::error(StatusCode::ParseError, "batch worker: a job line is not JSON");
  try {
    job->index = j.at("index").get<int>();
    job->id = j.at("id").get<std::string>();
    const std::string kind = j.at("kind").get<std::string>();
    bool known = false;
    for (BatchKind k : {BatchKind::Retarget, BatchKind::Transfer, BatchKind::Edit, BatchKind::Merge})
      if (kind == batch_kind_name(k)) job->kind = k, known = true;
    if (!known) return Status::error(StatusCode::ParseError, "batch worker: unknown job kind '" + io::quote_input(kind, 40) + "'");
    job->label = j.value("label", "");
    job->files = j.at("files").get<std::map<std::string, std::string>>();
    job->clip = j.value("clip", "");
    job->options_json = j.at("options").dump();
    job->output = j.at("output").get<std::string>();
    job->group = j.value("group", "");
  } catch (const std::exception& e) {
    return Status::error(StatusCode::ParseError, io::cap_message(std::string("batch worker: job line: ") + e.what()));
  }
  return Status::success();
}

std::string batch_done_message(const BatchJobOutcome& o) {
  Json j;
  j["event"] = "done";
  j["index"] = o.index;
  j["status"] = o.status;
  j["message"] = o.message;
  j["metrics"] = o.metrics;
  j["warnings"] = o.warnings;
  j["time_ms"] = o.time_ms;
  j["precompute_ms"] = o.precompute_ms;
  j["reused"] = o.reused;
  return j.dump() + "\n";
}

bool parse_batch_done_message(const Json& j, BatchJobOutcome* o) {
  try {
    o->status = j.at("status").get<std::string>();
    o->message = j.value("message", "");
    if (j.contains("metrics") && j["metrics"].is_object()) o->metrics = j["metrics"];
    if (j.contains("warnings") && j["warnings"].is_array()) o->warnings = j["warnings"].get<std::vector<std::string>>();
    o->time_ms = j.value("time_ms", 0.0);
    o->precompute_ms = j.value("precompute_ms", 0.0);
    o->reused = j.value("reused", false);
  } catch (const std::exception&) {
    return false;
  }
  return o->status == "ok" || o->status == "failed";
}

// ---- flipped faces

FlipCounter::FlipCounter(const Eigen::MatrixXd& rest, const Eigen::MatrixXi& F) : F_(F), neighbours_(F.rows()) {
  // As transfer_metrics: faces around each edge, edges in (min, max) order, so that the sums
  // below add the same numbers in the same order.
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      edge_faces[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  for (const auto& [e, faces] : edge_faces)
    for (int f : faces)
      for (int g : faces)
        if (f != g) neighbours_[static_cast<size_t>(f)].push_back(g);
  const Eigen::VectorXd a = agreement(rest);
  agrees_at_rest_.resize(static_cast<size_t>(F.rows()));
  for (int f = 0; f < F.rows(); ++f) agrees_at_rest_[static_cast<size_t>(f)] = a[f] > 0.5;
}

Eigen::VectorXd FlipCounter::agreement(const Eigen::MatrixXd& V) const {
  Eigen::MatrixXd N(F_.rows(), 3);
  for (int f = 0; f < F_.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F_(f, 0)), b = V.row(F_(f, 1)), c = V.row(F_(f, 2));
    N.row(f) = (b - a).cross(c - a).transpose();
  }
  Eigen::VectorXd out(F_.rows());
  for (int f = 0; f < F_.rows(); ++f) {
    Eigen::RowVector3d m = Eigen::RowVector3d::Zero();
    for (int g : neighbours_[static_cast<size_t>(f)]) m += N.row(g);
    const double l = N.row(f).norm() * m.norm();
    out[f] = l > 0 ? N.row(f).dot(m) / l : 1.0;
  }
  return out;
}

int FlipCounter::count(const Eigen::MatrixXd& V) const {
  const Eigen::VectorXd a = agreement(V);
  int n = 0;
  for (int f = 0; f < F_.rows(); ++f) n += a[f] < 0 && agrees_at_rest_[static_cast<size_t>(f)];
  return n;
}

// ---- jobs

struct BatchWorker::RetargetContext {
  std::string group;
  Status status;
  io::LoadResult target;  // the target's document, for the GLB
  RetargetJobOptions opt;
  RetargetJob session;
  std::vector<std::string> warnings;
  std::unique_ptr<FlipCounter> flips;  // on the target's rest surface
};

BatchWorker::~BatchWorker() = default;

BatchJobOutcome BatchWorker::run(const BatchJob& job, const Progress& progress) {
  BatchJobOutcome o;
  o.index = job.index;
  o.id = job.id;
  o.label = job.label;
  o.kind = batch_kind_name(job.kind);
  o.output = job.output;
  const auto t0 = Clock::now();
  Status s = io::check_output_path(job.output);
  if (s.ok()) {
    switch (job.kind) {
      case BatchKind::Retarget: s = run_retarget(job, progress, &o); break;
      case BatchKind::Transfer: s = run_transfer(job, progress, &o); break;
      case BatchKind::Edit: s = run_edit(job, progress, &o); break;
      case BatchKind::Merge: s = run_merge(job, progress, &o); break;
    }
  }
  o.time_ms = ms_since(t0);
  o.status = s.ok() ? "ok" : "failed";
  if (!s.ok()) o.message = std::string("[") + status_code_name(s.code) + "] " + s.message;
  return o;
}

std::shared_ptr<BatchWorker::RetargetContext> BatchWorker::retarget_context(const BatchJob& job, const Progress& progress,
                                                                            BatchJobOutcome* o) {
  if (reuse_)
    for (auto it = contexts_.begin(); it != contexts_.end(); ++it)
      if ((*it)->group == job.group) {
        auto ctx = *it;
        contexts_.erase(it);
        contexts_.push_front(ctx);
        o->reused = true;
        return ctx;
      }
  auto ctx = std::make_shared<RetargetContext>();
  ctx->group = job.group;
  const auto t0 = Clock::now();
  Status& s = ctx->status;
  s = options_of(job, retarget_options(), &ctx->opt);
  std::string joints, map;
  if (s.ok() && job.files.count("target_joints")) s = read_text(file_of(job, "target_joints"), &joints);
  if (s.ok() && job.files.count("joint_map")) s = read_text(file_of(job, "joint_map"), &map);
  io::LoadResult src;
  if (s.ok()) s = (src = io::load_asset(file_of(job, "source"))).status;
  if (s.ok()) s = (ctx->target = io::load_asset(file_of(job, "target"))).status;
  if (s.ok()) {
    // Clip-independent preparation: the first clip, every frame (the job's clip and frame range
    // are sampled per job below).
    RetargetJobOptions prep = ctx->opt;
    prep.clip.clear();
    prep.first_frame = 0;
    prep.last_frame = -1;
    s = ctx->session.prepare(src.asset, ctx->target.asset, joints, map, prep, progress);
    ctx->warnings = ctx->session.warnings();
    if (s.ok()) ctx->flips = std::make_unique<FlipCounter>(ctx->session.target_rest(), ctx->session.target_faces());
  }
  o->precompute_ms = ms_since(t0);
  if (reuse_) {
    contexts_.push_front(ctx);
    if (contexts_.size() > 2) contexts_.pop_back();
  }
  return ctx;
}

namespace {

// The exported GLB: layout, morph targets, K and the measured error of the compact layout.
void export_metrics(const io::MorphAnimationReport& r, size_t bytes, Json* m) {
  (*m)["export_layout"] = r.compact ? "compact" : "frames";
  (*m)["export_bytes"] = static_cast<double>(bytes);
  (*m)["export_morph_targets"] = r.targets;
  if (!r.compact) return;
  (*m)["export_components"] = r.components;
  (*m)["export_max_error"] = r.max_error;
  (*m)["export_tolerance_met"] = !r.capped;
}

double height(const Eigen::MatrixXd& V) { return V.rows() ? V.col(1).maxCoeff() - V.col(1).minCoeff() : 0.0; }

// Metrics every retarget job reports: frames, flipped faces against the rest pose (worst
// frame), the error against ground truth when the target has its own clip of that name (the
// same character: self-retargeting, Eq. 19; a character with the same rig and clips), bone
// lengths (harmonic).
void retarget_metrics(const BatchJob& job, const RetargetJob& session, const FlipCounter& flips, const std::string& clip_name,
                      const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                      const std::vector<Eigen::MatrixXd>* joints, Json* m) {
  (*m)["frames"] = static_cast<int>(frames.size());
  int flipped = 0;
  for (const Eigen::MatrixXd& V : frames) flipped = std::max(flipped, flips.count(V));
  (*m)["flipped_faces_max"] = flipped;
  if (const AnimatedCharacter* tc = session.target_character()) {
    int clip = -1;
    if (find_clip(*tc, clip_name, &clip).ok() && tc->V_rest.rows() == session.target_rest().rows()) {
      std::vector<Eigen::MatrixXd> gt;
      for (double t : times) gt.push_back(pose_at(*tc, clip, t));
      const SequenceError e = sequence_vertex_error(frames, gt, height(session.target_rest()));
      const bool self = file_of(job, "source") == file_of(job, "target");
      (*m)[self ? "self_retargeting_error" : "ground_truth_error"] = e.mean;
      (*m)[self ? "self_retargeting_error_max_frame" : "ground_truth_error_max_frame"] = e.max;
    }
  }
  if (joints) {
    const HarmonicRetargeter& H = session.harmonic();
    const BoneLengthError be = bone_length_error(*joints, H.bones(), H.rest_bone_lengths());
    (*m)["bone_length_error_mean"] = be.mean;
    (*m)["bone_length_error_max"] = be.max;
  }
}

}  // namespace

Status BatchWorker::run_retarget(const BatchJob& job, const Progress& progress, BatchJobOutcome* o) {
  RetargetJobOptions opt;
  if (Status s = options_of(job, retarget_options(), &opt); !s.ok()) return s;
  std::vector<uint8_t> bytes;
  std::vector<Eigen::MatrixXd> frames;

  if (opt.method == RetargetMethod::Lbs) {  // no shared state to reuse: one RetargetJob per clip
    const auto t0 = Clock::now();
    io::LoadResult src = io::load_asset(file_of(job, "source"));
    if (!src.status.ok()) return src.status;
    io::LoadResult tgt = io::load_asset(file_of(job, "target"));
    if (!tgt.status.ok()) return tgt.status;
    std::string joints, map;
    if (job.files.count("target_joints"))
      if (Status s = read_text(file_of(job, "target_joints"), &joints); !s.ok()) return s;
    if (job.files.count("joint_map"))
      if (Status s = read_text(file_of(job, "joint_map"), &map); !s.ok()) return s;
    RetargetJob session;
    opt.clip = job.clip;
    if (Status s = session.prepare(src.asset, tgt.asset, joints, map, opt, progress.sub(0, 0.3)); !s.ok()) return s;
    o->precompute_ms = ms_since(t0);
    o->warnings = session.warnings();
    if (Status s = session.frames(0, session.num_frames(), &frames, progress.sub(0.3, 0.9)); !s.ok()) return s;
    io::MorphAnimationReport report;
    if (Status s = session.write_glb(frames, session.times(), &bytes, &report); !s.ok()) return s;
    if (Status s = io::write_file_atomic(job.output, bytes); !s.ok()) return s;
    export_metrics(report, bytes.size(), &o->metrics);
    retarget_metrics(job, session, FlipCounter(session.target_rest(), session.target_faces()), session.clip_name(), frames,
                     session.times(), nullptr, &o->metrics);
    return Status::success();
  }

  const std::shared_ptr<RetargetContext> ctx = retarget_context(job, progress.sub(0, 0.5), o);
  if (!ctx->status.ok()) return ctx->status;
  o->warnings = ctx->warnings;
  const RetargetJob& session = ctx->session;
  const AnimatedCharacter& source = session.source_character();
  // The job's clip and frames, as RetargetJob::prepare samples them.
  int clip = -1;
  if (Status s = find_clip(source, job.clip, &clip); !s.ok()) return s;
  const AnimationClip& c = source.clips[static_cast<size_t>(clip)];
  const std::vector<double> all = frame_times(c, opt.fps);
  const int n = static_cast<int>(all.size());
  const int a = std::max(0, opt.first_frame), b = opt.last_frame < 0 ? n : std::min(n, opt.last_frame);
  if (a >= b)
    return Status::error(StatusCode::InvalidArgument, "frame range " + std::to_string(opt.first_frame) + ":" +
                                                          std::to_string(opt.last_frame) + " is empty (the clip has " +
                                                          std::to_string(n) + " frames at " + std::to_string(opt.fps) + " fps)");
  const std::vector<double> times(all.begin() + a, all.begin() + b);
  std::vector<Eigen::MatrixXd> joints;
  const Progress fp = progress.sub(0.5, 0.9);
  for (size_t k = 0; k < times.size(); ++k) {
    if (!fp.update("frames", double(k) / double(times.size()))) return cancelled_status("frames");
    RetargetFrame f = session.harmonic().retarget(pose_at(source, clip, times[k]));
    if (!f.status.ok()) return f.status;
    frames.push_back(std::move(f.V));
    joints.push_back(std::move(f.joints));
  }
  RetargetJobOptions export_opt = opt;  // this job's export settings, the pair's props setting
  export_opt.props_follow = ctx->opt.props_follow;
  io::MorphAnimationReport report;
  if (Status s = write_retarget_glb(ctx->target.asset, session.target_character(), export_opt, c.name, frames, times, &bytes,
                                    &report);
      !s.ok())
    return s;
  export_metrics(report, bytes.size(), &o->metrics);
  if (Status s = io::write_file_atomic(job.output, bytes); !s.ok()) return s;
  progress.sub(0.9, 1).update("metrics", 0);
  retarget_metrics(job, session, *ctx->flips, c.name, frames, times, &joints, &o->metrics);
  return Status::success();
}

Status BatchWorker::run_transfer(const BatchJob& job, const Progress& progress, BatchJobOutcome* o) {
  PoseTransferOptions opt;
  if (Status s = options_of(job, transfer_options(), &opt); !s.ok()) return s;
  TransferJobFiles files;
  files.reference = file_of(job, "reference");
  files.source = file_of(job, "source");
  files.landmarks = file_of(job, "landmarks");
  files.cage = file_of(job, "cage");
  files.out = job.output;
  const TransferJobResult r = run_transfer_job(files, opt, progress);
  if (!r.status.ok()) return r.status;
  Json& m = o->metrics;
  const io::LoadResult src = io::load_asset(files.source);
  if (src.status.ok()) {
    const Mesh S = src.asset.mesh();
    const TransferMetrics t = transfer_metrics(r.transfer.V, S.V, S.F);
    m["flipped_faces"] = t.flipped_faces;
    m["laplacian_change"] = t.laplacian_change;
    m["edge_distortion_mean"] = t.edge_distortion_mean;
    m["edge_distortion_max"] = t.edge_distortion_max;
    if (job.files.count("ground_truth")) {
      // Ground truth in its own frame (Sumner's lion poses): compared after removing the centroid offset.
      const io::LoadResult gt = io::load_asset(file_of(job, "ground_truth"));
      if (!gt.status.ok()) {
        o->warnings.push_back("ground truth: " + gt.status.message);
      } else if (gt.asset.weld.V.rows() != r.transfer.V.rows()) {
        o->warnings.push_back("ground truth has " + std::to_string(gt.asset.weld.V.rows()) + " vertices, the result " +
                              std::to_string(r.transfer.V.rows()) + ": not compared");
      } else {
        const Eigen::MatrixXd& G = gt.asset.weld.V;
        const Eigen::RowVector3d offset = G.colwise().mean() - r.transfer.V.colwise().mean();
        const Eigen::MatrixXd centred = r.transfer.V.rowwise() + offset;
        const TransferMetrics g = transfer_metrics(centred, G, S.F);
        m["ground_truth_error"] = g.vertex_error_mean;
        m["ground_truth_error_max"] = g.vertex_error_max;
      }
    }
  }
  m["iterations"] = r.transfer.iterations;
  m["converged"] = r.transfer.converged;
  m["landmarks"] = static_cast<int>(r.transfer.landmarks.size());
  return Status::success();
}

Status BatchWorker::run_edit(const BatchJob& job, const Progress& progress, BatchJobOutcome* o) {
  EditJobOptions probe;
  if (Status s = options_of(job, edit_options(), &probe); !s.ok()) return s;
  EditJobRequest req;
  req.files = {file_of(job, "input"), file_of(job, "spec"), job.output};
  req.set_overrides = [&job](EditJobOptions& opt) { return options_of(job, edit_options(), &opt); };
  const EditJobResult r = run_edit_job(req, progress);
  if (!r.status.ok()) return r.status;
  Json& m = o->metrics;
  m["vertices"] = r.vertices;
  m["handles"] = r.handles;
  m["inverted_faces"] = r.inverted_faces;
  m["rigidity_error"] = r.rigidity_error;
  m["edge_distortion_mean"] = r.edge_distortion_mean;
  m["edge_distortion_max"] = r.edge_distortion_max;
  return Status::success();
}

Status BatchWorker::run_merge(const BatchJob& job, const Progress& progress, BatchJobOutcome* o) {
  MergeOptions probe;
  if (Status s = options_of(job, merge_options(), &probe); !s.ok()) return s;
  MergeJobRequest req;
  req.files = {file_of(job, "target"), file_of(job, "source"), file_of(job, "spec"), job.output};
  req.set_overrides = [&job](MergeOptions& opt) { return options_of(job, merge_options(), &opt); };
  const MergeJobResult r = run_merge_job(req, progress);
  if (!r.status.ok()) return r.status;
  Json& m = o->metrics;
  m["vertices"] = r.vertices;
  m["faces"] = r.faces;
  m["boundary_loops"] = r.boundary_loops;
  m["nonmanifold_edges"] = r.nonmanifold_edges;
  int flipped = 0;
  double min_angle = 180, dihedral = 0;
  for (const MergeSeamReport& z : r.stats.seams) {
    flipped += z.flipped_faces;
    min_angle = std::min(min_angle, z.min_angle_deg);
    dihedral = std::max(dihedral, z.dihedral_max_deg);
  }
  if (!r.stats.seams.empty()) {
    m["seam_flipped_faces"] = flipped;
    m["seam_min_angle_deg"] = min_angle;
    m["seam_dihedral_max_deg"] = dihedral;
  }
  return Status::success();
}

// ---- the worker process

#ifndef __EMSCRIPTEN__
bool write_fd_all(int fd, const std::string& s) {
  size_t done = 0;
  while (done < s.size()) {
    const ssize_t w = ::write(fd, s.data() + done, s.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    done += static_cast<size_t>(w);
  }
  return true;
}

int run_batch_worker_loop(int in_fd, int out_fd, bool reuse) {
  BatchWorker worker(reuse);
  // Test seam (tests/batch_test.cpp): the job with this id aborts its worker, as a crash would.
  const char* crash = std::getenv("MESHMORPH_BATCH_CRASH");
  std::string buffer;
  char chunk[4096];
  for (;;) {
    size_t nl;
    while ((nl = buffer.find('\n')) == std::string::npos) {
      const ssize_t r = ::read(in_fd, chunk, sizeof chunk);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) return 0;  // the batch closed our input: done
      buffer.append(chunk, static_cast<size_t>(r));
    }
    const std::string line = buffer.substr(0, nl);
    buffer.erase(0, nl + 1);
    BatchJob job;
    BatchJobOutcome o;
    if (Status s = parse_batch_job_message(line, &job); !s.ok()) {
      std::fprintf(stderr, "%s\n", s.message.c_str());
      return 2;
    }
    if (crash && job.id == crash) std::abort();
    auto last = Clock::now() - std::chrono::seconds(1);
    std::mutex mutex;  // pose_transfer reports from its cage thread too
    const int index = job.index;
    const Progress progress([&, index](const std::string&, double f) {
      const std::lock_guard<std::mutex> lock(mutex);
      const auto now = Clock::now();
      if (now - last < std::chrono::milliseconds(100)) return true;
      last = now;
      char msg[96];
      std::snprintf(msg, sizeof msg, "{\"event\":\"progress\",\"index\":%d,\"f\":%.3f}\n", index, std::clamp(f, 0.0, 1.0));
      write_fd_all(out_fd, msg);
      return true;
    });
    o = worker.run(job, progress);
    if (!write_fd_all(out_fd, batch_done_message(o))) return 1;
  }
}
#else
int run_batch_worker_loop(int, int, bool) { return 2; }
#endif

}  // namespace mm::app
