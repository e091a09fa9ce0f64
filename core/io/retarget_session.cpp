#include "io/retarget_session.h"

#include <algorithm>

#include "io/gltf_document.h"

namespace mm::io {

Status RetargetSession::prepare(const Asset& source, const Asset& target, const std::string& target_joints_json,
                                const std::string& joint_map_json, const RetargetJobOptions& opt,
                                const Progress& progress) {
  opt_ = opt;
  warnings_.clear();
  times_.clear();
  CharacterOptions co;
  co.surface = opt.surface;
  CharacterResult src = animated_character(source, co);
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
  target_is_gltf_ = gltf_model(target) != nullptr;
  JointSet target_joints;
  if (target_is_gltf_) {
    CharacterResult tr = animated_character(target, co);
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
  if (!target_joints_json.empty()) {
    JointSetResult jr = parse_joints_json(target_joints_json);
    if (!jr.status.ok()) return Status{jr.status.code, "target joints: " + jr.status.message};
    target_joints = std::move(jr.joints);
  }
  if (target_joints.size() == 0)
    return Status::error(StatusCode::InvalidArgument,
                         "the target has no skin: give its joints with a JSON file {\"joint name\": [x, y, z]} "
                         "using the source's joint names");
  std::map<std::string, std::string> map;
  if (!joint_map_json.empty()) {
    JointMapResult mr = parse_joint_map_json(joint_map_json);
    if (!mr.status.ok()) return mr.status;
    map = std::move(mr.source_to_target);
  }
  const JointSet source_joints = character_joints(source_);
  RetargetCharacter S{source_.V_rest, source_.F, source_joints};
  RetargetCharacter T{target_V_, target_F_, target_joints};
  if (opt.method == RetargetMethod::Harmonic) {
    s = harmonic_.precompute(S, T, map, opt.harmonic, progress);
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

Eigen::MatrixXd RetargetSession::source_frame(int k) const { return pose_at(source_, clip_, times_[k]); }

Status RetargetSession::frame(int k, Eigen::MatrixXd* V) const {
  if (k < 0 || k >= num_frames()) return Status::error(StatusCode::InvalidArgument, "frame index out of range");
  if (opt_.method == RetargetMethod::Harmonic) {
    RetargetFrame f = harmonic_.retarget(source_frame(k));
    if (!f.status.ok()) return f.status;
    *V = std::move(f.V);
    return Status::success();
  }
  const Matrix4dList world = node_world_matrices(source_, clip_, times_[k]);
  *V = lbs_retarget(target_V_, align_, lbs_weights_, node_motions(source_, world));
  if (!V->allFinite()) return Status::error(StatusCode::NumericalError, "LBS frame is not finite");
  return Status::success();
}

Status RetargetSession::frames(int first, int count, std::vector<Eigen::MatrixXd>* out, const Progress& progress) const {
  out->clear();
  for (int k = first; k < first + count && k < num_frames(); ++k) {
    if (!progress.update("frames", count > 0 ? double(k - first) / count : 1.0)) return cancelled_status("frames");
    Eigen::MatrixXd V;
    Status s = frame(k, &V);
    if (!s.ok()) return s;
    out->push_back(std::move(V));
  }
  progress.update("frames", 1.0);
  return Status::success();
}

Status RetargetSession::write_glb(const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                                  std::vector<uint8_t>* bytes) const {
  MorphAnimationOptions mo;
  mo.animation_name = clip_name_.empty() ? "retarget" : clip_name_;
  return write_morph_animation(target_asset_, target_character(), frames, times, bytes, mo);
}

}  // namespace mm::io
