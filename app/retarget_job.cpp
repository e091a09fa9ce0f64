#include "app/retarget_job.h"

#include <algorithm>
#include <array>
#include <limits>

#include "app/joints_job.h"
#include "character/prop_tracks.h"
#include "io/gltf_document.h"
#include "io/joints_json.h"
#include "metrics/retarget_metrics.h"
#include "retarget/joint_fitting.h"

namespace mm::app {

const OptionSchema<RetargetJobOptions>& retarget_options() {
  using O = RetargetJobOptions;
  static const OptionSchema<O> schema = [] {
    OptionSchema<O> s("retarget", "animate a target mesh with a source character's clip (harmonic maps, paper 002)");
    s.text("clip", [](O& o) -> std::string& { return o.clip; }, "source clip name (\"\" = the first clip)");
    s.number("fps", [](O& o) -> double& { return o.fps; }, 1e-3, 1000, "sampling rate of the clip");
    s.integer("first_frame", [](O& o) -> int& { return o.first_frame; }, 0, kUnbounded, "first frame of the sampled clip");
    s.integer("last_frame", [](O& o) -> int& { return o.last_frame; }, -1, kUnbounded, "end of the frame range, exclusive (-1 = to the end)");
    s.choice<RetargetMethod>("method", [](O& o) -> RetargetMethod& { return o.method; },
                             {{"harmonic", RetargetMethod::Harmonic}, {"lbs", RetargetMethod::Lbs}},
                             "harmonic map (paper 002) or the naive LBS baseline (Fig. 6 f)");
    s.choice<io::SurfaceSelection>("surface", [](O& o) -> io::SurfaceSelection& { return o.surface; },
                                   {{"auto", io::SurfaceSelection::Auto}, {"skinned", io::SurfaceSelection::SkinnedOnly},
                                    {"all", io::SurfaceSelection::All}},
                                   "which glTF primitives form each character");
    s.integer("num_singularities", [](O& o) -> int& { return o.harmonic.map.singularities.count; }, 4, 20000,
              "MFS singularity points per character (Sec. 4.3: 260)");
    s.integer("num_collocation", [](O& o) -> int& { return o.harmonic.map.num_collocation; }, 4, 200000,
              "MFS collocation points per character");
    s.number("offset", [](O& o) -> double& { return o.harmonic.map.singularities.offset; }, 1e-6, 1,
             "offset surface distance for the singularities, × bbox diagonal");
    s.number("w_position", [](O& o) -> double& { return o.harmonic.w_position; }, 0, kUnbounded, "λ_position, anchor trajectory weight");
    s.number("w_smooth", [](O& o) -> double& { return o.harmonic.w_smooth; }, 0, kUnbounded, "λ_smooth, Hessian energy weight");
    s.number("w_bone", [](O& o) -> double& { return o.harmonic.w_bone; }, 0, kUnbounded, "λ_bone, bone-length preservation weight");
    s.number("w_affine", [](O& o) -> double& { return o.harmonic.w_affine; }, 0, kUnbounded, "λ_affine, Jacobian match weight");
    s.integer("bone_iterations", [](O& o) -> int& { return o.harmonic.bone_iterations; }, 0, 100,
              "re-linearisations of the bone-length term");
    s.integer("surface_descriptors", [](O& o) -> int& { return o.harmonic.surface_descriptors; }, 0, 100000,
              "target surface points with affine descriptors (0 = joints only)");
    s.text("anchor_joint", [](O& o) -> std::string& { return o.harmonic.anchor_joint; },
           "joint whose (scaled) trajectory the target follows (\"\" = the shallowest)");
    s.choice<bool>("articulated_base", [](O& o) -> bool& { return o.harmonic.articulated_base; },
                   {{"on", true}, {"off", false}},
                   "bones' motions (fitted on the source each frame) carry the surfaces; the harmonic "
                   "maps add the rest (off: the paper's maps alone)");
    s.choice<bool>("target_weights", [](O& o) -> bool& { return o.harmonic.base_target_skin; },
                   {{"skin", true}, {"transferred", false}},
                   "the articulated base's weights on a rigged target: its own skin, or the source's carried over");
    s.number("target_smoothing", [](O& o) -> double& { return o.harmonic.base_target_smoothing; }, 0, 1,
             "carried-over target weights diffused over about this × the target's diagonal (0 = off)");
    s.choice<bool>("base_weights", [](O& o) -> bool& { return o.harmonic.base_skin_weights; },
                   {{"skin", true}, {"learned", false}},
                   "the articulated base's bone weights: the source's own skin, or learned from poses over all its clips");
    s.choice<bool>("context_graph", [](O& o) -> bool& { return o.harmonic.context_graph; },
                   {{"on", true}, {"off", false}},
                   "context graph terms E_spatial and E_volume (Sec. 6, Eq. 11-12)");
    s.number("w_spatial", [](O& o) -> double& { return o.harmonic.w_spatial; }, 0, kUnbounded,
             "λ_spatial, context-graph Laplacian weight (Sec. 7.2: 0.8)");
    s.number("w_volume", [](O& o) -> double& { return o.harmonic.w_volume; }, 0, kUnbounded,
             "λ_volume, volume-graph Laplacian weight (Sec. 7.2: 1)");
    s.number("w_volume_base", [](O& o) -> double& { return o.harmonic.w_volume_base; }, 0, kUnbounded,
             "λ_volume with the articulated base (it keeps the volume already; the term then damps the maps' residual)");
    s.number("graph_max_edge", [](O& o) -> double& { return o.harmonic.graph.max_edge_length; }, 0, 10,
             "context graph: edges longer than this × the height are pruned (Sec. 6.1: 0.5)");
    s.integer("graph_frames", [](O& o) -> int& { return o.graph_frames; }, 0, 10000,
              "context graph: clip frames whose pruned graphs join the fixed topology (0 = rest pose only)");
    s.boolean("props_follow", [](O& o) -> bool& { return o.props_follow; },
              "exported GLB: props under joints (weapons, hats) follow the surface");
    s.choice<io::MorphExport>("export", [](O& o) -> io::MorphExport& { return o.export_layout; },
                              {{"auto", io::MorphExport::Auto}, {"frames", io::MorphExport::Frames},
                               {"compact", io::MorphExport::Compact}},
                              "exported GLB: one morph target per frame, or a PCA basis + weights (compact; auto: "
                              "compact above 60 frames)");
    s.number("export_tolerance", [](O& o) -> double& { return o.export_tolerance; }, 1e-7, 0.1,
             "compact export: max vertex distance to any frame, × the target's size");
    s.integer("export_max_components", [](O& o) -> int& { return o.export_max_components; }, 1, 4096,
              "compact export: at most this many morph components (the tolerance is reported as missed above)");
    return s;
  }();
  return schema;
}

Status RetargetJob::prepare(const io::Asset& source, const io::Asset& target, const std::string& target_joints_json,
                                const std::string& joint_map_json, const RetargetJobOptions& opt,
                                const Progress& progress) {
  opt_ = opt;
  warnings_.clear();
  times_.clear();
  io::CharacterOptions co;
  co.surface = opt.surface;
  io::CharacterResult src = io::animated_character(source, co);
  if (!src.status.ok()) return Status{src.status.code, "source: " + src.status.message};
  source_ = std::move(src.character);
  for (auto& w : src.warnings) warnings_.push_back("source: " + w);
  if (source_.main_skin < 0)
    return Status::error(StatusCode::InvalidArgument, "the source '" + source.source_name + "' has no skin (no joints)");
  Status s = find_clip(source_, opt.clip, &clip_);
  if (!s.ok()) return s;
  clip_name_ = source_.clips[clip_].name;
  if (!(opt.fps > 0 && opt.fps <= 1000)) return Status::error(StatusCode::InvalidArgument, "fps must be in (0, 1000]");
  std::vector<double> all = frame_times(source_.clips[clip_], opt.fps);
  const int n = static_cast<int>(all.size());
  const int a = std::max(0, opt.first_frame), b = opt.last_frame < 0 ? n : std::min(n, opt.last_frame);
  if (a >= b)
    return Status::error(StatusCode::InvalidArgument, "frame range " + std::to_string(opt.first_frame) + ":" +
                                                          std::to_string(opt.last_frame) + " is empty (the clip has " +
                                                          std::to_string(n) + " frames at " + std::to_string(opt.fps) + " fps)");
  times_.assign(all.begin() + a, all.begin() + b);

  // Target surface and joints.
  target_asset_ = target;
  target_is_gltf_ = io::gltf_model(target) != nullptr;
  JointSet target_joints;
  if (target_is_gltf_) {
    io::CharacterResult tr = io::animated_character(target, co);
    if (!tr.status.ok()) return Status{tr.status.code, "target: " + tr.status.message};
    target_ = std::move(tr.character);
    for (auto& w : tr.warnings) warnings_.push_back("target: " + w);
    target_V_ = target_.V_rest;
    target_F_ = target_.F;
    target_joints = character_joints(target_);
  } else {
    target_V_ = target.V_raw;
    target_F_ = target.F_raw;
  }
  if (target_joints_json == "auto") {
    // Automatic joints (issue 14): the joints job's fit, read back from its JSON as a joints file
    // is, so that the CLI, `meshmorph joints` and the page (which sends that JSON) get the same joints.
    JointsJobOptions jo;
    jo.surface = opt.surface;
    const JointsJobResult fit = run_joints_job(source, target, "", jo, progress.sub(0, 0.3));
    if (!fit.status.ok()) return Status{fit.status.code, "automatic target joints: " + fit.status.message};
    for (const auto& w : fit.warnings) warnings_.push_back("automatic joints: " + w);
    io::JointSetResult jr = io::parse_joints_json(fit.json);
    if (!jr.status.ok()) return Status{jr.status.code, "automatic target joints: " + jr.status.message};
    target_joints = std::move(jr.joints);
  } else if (!target_joints_json.empty()) {
    io::JointSetResult jr = io::parse_joints_json(target_joints_json);
    if (!jr.status.ok()) return Status{jr.status.code, "target joints: " + jr.status.message};
    target_joints = std::move(jr.joints);
  }
  if (target_joints.size() == 0)
    return Status::error(StatusCode::InvalidArgument,
                         "the target has no skin: give its joints with a JSON file {\"joint name\": [x, y, z]} "
                         "using the source's joint names");
  std::map<std::string, std::string> map;
  if (!joint_map_json.empty()) {
    io::JointMapResult mr = io::parse_joint_map_json(joint_map_json);
    if (!mr.status.ok()) return mr.status;
    map = std::move(mr.source_to_target);
  }
  const JointSet source_joints = character_joints(source_);
  RetargetCharacter S{source_.V_rest, source_.F, source_joints, joint_skin_weights(source_, source_joints)};
  // The target's own skin only with its own joints (auto or JSON joints treat it as unrigged).
  const bool own_rig = target_is_gltf_ && target_joints_json.empty();
  RetargetCharacter T{target_V_, target_F_, target_joints, own_rig ? joint_skin_weights(target_, target_joints) : SkinWeights{}};
  // Multi-part characters interpenetrate at rest by design: per-frame counts leave those pairs out.
  rest_intersections_ = intersecting_triangle_pairs(target_V_, target_F_);
  if (opt.method == RetargetMethod::Harmonic) {
    std::vector<Eigen::MatrixXd> gf;
    if (opt.harmonic.context_graph && opt.graph_frames > 0) {
      const int nf = num_frames(), k = std::min(opt.graph_frames, nf);
      for (int i = 0; i < k; ++i) gf.push_back(source_frame(k > 1 ? i * (nf - 1) / (k - 1) : 0));
    }
    harmonic_.set_graph_frames(std::move(gf));
    // With base_weights "learned" the articulated base learns the source's bone weights from poses
    // spread evenly over all of its clips end to end (not only the chosen one): the weights, and
    // so every clip's result, do not depend on which clip was prepared (the batch worker reuses
    // one preparation). By default they come from the source's own skin.
    std::vector<Eigen::MatrixXd> bf;
    if (opt.harmonic.articulated_base && !opt.harmonic.base_skin_weights && opt.harmonic.base_frames > 0 &&
        !source_.clips.empty()) {
      double total = 0;
      for (const AnimationClip& c : source_.clips) total += std::max(0.0, c.end - c.start);
      const int k = opt.harmonic.base_frames;
      for (int i = 0; i < k; ++i) {
        double at = (i + 0.5) * total / k;
        for (size_t c = 0; c < source_.clips.size(); ++c) {
          const double len = std::max(0.0, source_.clips[c].end - source_.clips[c].start);
          if (at <= len || c + 1 == source_.clips.size()) {
            bf.push_back(pose_at(source_, static_cast<int>(c), source_.clips[c].start + std::min(at, len)));
            break;
          }
          at -= len;
        }
      }
    }
    harmonic_.set_base_frames(std::move(bf));
    s = harmonic_.precompute(S, T, map, opt.harmonic, target_joints_json == "auto" ? progress.sub(0.3, 1) : progress);
    if (!s.ok()) return s;
    for (auto& w : harmonic_.warnings()) warnings_.push_back(w);
    return Status::success();
  }
  // LBS baseline: align rest poses on matched joints, transfer weights by closest point.
  JointMatchResult match = match_joints(source_joints, target_joints, map, 2);
  if (!match.status.ok()) return match.status;
  align_ = align_rest_poses(source_joints, target_joints, match.pairs, source_.V_rest, target_V_);
  SkinTransferResult st = transfer_skin_weights(source_.V_rest, source_.F, character_skin_weights(source_),
                                                align_.apply(target_V_));
  if (!st.status.ok()) return st.status;
  lbs_weights_ = std::move(st.weights);
  return Status::success();
}

Eigen::MatrixXd RetargetJob::source_frame(int k) const { return pose_at(source_, clip_, times_[k]); }

Status RetargetJob::frame(int k, Eigen::MatrixXd* V) const { return frame(k, V, nullptr); }

Status RetargetJob::frame(int k, Eigen::MatrixXd* V, Eigen::MatrixXd* joints) const {
  if (k < 0 || k >= num_frames()) return Status::error(StatusCode::InvalidArgument, "frame index out of range");
  if (joints) joints->resize(0, 3);
  if (opt_.method == RetargetMethod::Harmonic) {
    RetargetFrame f = harmonic_.retarget(source_frame(k));
    if (!f.status.ok()) return f.status;
    *V = std::move(f.V);
    if (joints) *joints = std::move(f.joints);
    return Status::success();
  }
  const Matrix4dList world = node_world_matrices(source_, clip_, times_[k]);
  *V = lbs_retarget(target_V_, align_, lbs_weights_, node_motions(source_, world));
  if (!V->allFinite()) return Status::error(StatusCode::NumericalError, "LBS frame is not finite");
  return Status::success();
}

Status RetargetJob::frames(int first, int count, std::vector<Eigen::MatrixXd>* out, const Progress& progress,
                           FrameChecks* checks) const {
  out->clear();
  if (checks) *checks = {};
  for (int k = first; k < first + count && k < num_frames(); ++k) {
    if (!progress.update("frames", count > 0 ? double(k - first) / count : 1.0)) return cancelled_status("frames");
    Eigen::MatrixXd V, J;
    Status s = frame(k, &V, checks ? &J : nullptr);
    if (!s.ok()) return s;
    if (checks) {
      checks->bone_length_error.push_back(
          J.rows() > 0 ? bone_length_error({J}, harmonic_.bones(), harmonic_.rest_bone_lengths()).mean
                       : std::numeric_limits<double>::quiet_NaN());
      checks->self_intersections.push_back(self_intersection_count(V, target_F_, rest_intersections_));
    }
    out->push_back(std::move(V));
  }
  progress.update("frames", 1.0);
  return Status::success();
}

std::vector<io::DebugGeometry> RetargetJob::context_graph_overlay() const {
  std::vector<io::DebugGeometry> sets;
  if (opt_.method != RetargetMethod::Harmonic || !harmonic_.has_context_graph()) return sets;
  const ContextGraphInfo& g = harmonic_.context_graph();
  io::DebugGeometry sn, se, tn, te, vn, ve;
  sn.name = "source graph nodes";
  sn.P = g.source_nodes;
  sn.color = {1, 0.2f, 0.1f, 1};
  se.name = "source graph edges";
  se.P = g.source_nodes;
  se.lines = g.edges;
  se.color = {1, 0.6f, 0.1f, 1};
  tn.name = "target graph nodes";
  tn.P = g.target_nodes;
  tn.color = {0.1f, 0.4f, 1, 1};
  te.name = "target graph edges";
  te.P = g.target_nodes;
  te.lines = g.edges;
  te.color = {0.2f, 0.8f, 1, 1};
  vn.name = "target volume graph nodes";
  vn.P = g.volume_nodes;
  vn.color = {0.3f, 0.9f, 0.3f, 1};
  ve.name = "target volume graph edges";
  ve.P = g.volume_nodes;
  ve.lines = g.volume_edges;
  ve.color = {0.3f, 0.7f, 0.3f, 0.6f};
  for (auto* d : {&sn, &se, &tn, &te, &vn, &ve})
    if (d->P.rows() > 0 && (d->lines.size() > 0 || d == &sn || d == &tn || d == &vn)) sets.push_back(*d);
  // One point set per body part (source nodes), colours cycling through a small palette.
  const std::array<std::array<float, 4>, 8> palette{{{0.9f, 0.1f, 0.1f, 1}, {0.1f, 0.7f, 0.1f, 1}, {0.1f, 0.2f, 0.9f, 1},
                                                     {0.9f, 0.8f, 0.1f, 1}, {0.8f, 0.1f, 0.8f, 1}, {0.1f, 0.8f, 0.8f, 1},
                                                     {0.5f, 0.3f, 0.1f, 1}, {0.5f, 0.5f, 0.5f, 1}}};
  const int np = g.part.size() > 0 ? g.part.maxCoeff() + 1 : 0;
  const JointSet sj = character_joints(source_);
  for (int p = 0; p < np; ++p) {
    std::vector<int> rows;
    for (int i = 0; i < g.part.size(); ++i)
      if (g.part[i] == p) rows.push_back(i);
    if (rows.empty()) continue;
    io::DebugGeometry d;
    const JointPair& jp = harmonic_.used_joints()[p];
    d.name = "part " + std::to_string(p) + " (" + sj.names[jp.source] + ")";
    d.P.resize(static_cast<Eigen::Index>(rows.size()), 3);
    for (size_t r = 0; r < rows.size(); ++r) d.P.row(r) = g.source_nodes.row(rows[r]);
    d.color = palette[p % palette.size()];
    sets.push_back(std::move(d));
  }
  return sets;
}

Status RetargetJob::debug_graph_glb(std::vector<uint8_t>* bytes) const {
  const std::vector<io::DebugGeometry> sets = context_graph_overlay();
  if (sets.empty())
    return Status::error(StatusCode::InvalidArgument, "no context graph: use the harmonic method with context_graph on");
  return io::debug_geometry_glb(sets, bytes);
}

Status write_retarget_glb(const io::Asset& target, const AnimatedCharacter* target_character,
                          const RetargetJobOptions& opt, const std::string& clip_name,
                          const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                          std::vector<uint8_t>* bytes, io::MorphAnimationReport* report) {
  io::MorphAnimationOptions mo;
  mo.animation_name = clip_name.empty() ? "retarget" : clip_name;
  mo.layout = opt.export_layout;
  mo.tolerance = opt.export_tolerance;
  mo.max_components = opt.export_max_components;
  std::vector<NodeTrack> tracks;
  if (opt.props_follow && target_character) tracks = prop_tracks(*target_character, frames);
  return io::write_morph_animation(target, target_character, frames, times, bytes, mo, tracks, report);
}

Status RetargetJob::write_glb(const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                              std::vector<uint8_t>* bytes, io::MorphAnimationReport* report) const {
  return write_retarget_glb(target_asset_, target_character(), opt_, clip_name_, frames, times, bytes, report);
}

}  // namespace mm::app
