// The retarget job (paper 002): source character and clip, target (glTF with or without a skin,
// or a plain mesh with joints from JSON), harmonic or LBS method, frames, and the animated GLB
// (with the props' rigid motions) — shared by the CLI, the wasm binding and the bench so that
// they stay thin. Precompute once (prepare), then frames in any order or batch.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"
#include "io/asset.h"
#include "io/debug_lines_glb.h"
#include "app/option_schema.h"
#include "character/animated_character.h"
#include "io/gltf_animation.h"
#include "retarget/harmonic_retarget.h"
#include "retarget/lbs_baseline.h"

namespace mm::app {

enum class RetargetMethod {
  Harmonic,  // paper 002 (retarget/harmonic_retarget.h)
  Lbs,       // baseline: source skin weights on the target (retarget/lbs_baseline.h)
};

struct RetargetJobOptions {
  std::string clip;                 // source clip name; "" = the first clip
  double fps = 30;                  // frame rate of the sampled clip
  int first_frame = 0;              // frame range [first_frame, last_frame) of the sampled clip
  int last_frame = -1;              // -1 = to the end
  RetargetMethod method = RetargetMethod::Harmonic;
  HarmonicRetargetOptions harmonic; // method options (paper defaults, see harmonic_retarget.h)
  io::SurfaceSelection surface = io::SurfaceSelection::Auto;  // which glTF primitives form each character
  bool props_follow = true;         // exported GLB: joints that carry props follow the surface (prop_tracks)
  io::MorphExport export_layout = io::MorphExport::Auto;  // exported GLB: one morph target per frame,
                                    // or compact (PCA basis + weights), or compact above 60 frames
  double export_tolerance = 1e-3;   // compact export: max vertex distance to any frame, × target size
  int export_max_components = 64;   // compact export: at most this many components (K)
  int graph_frames = 8;             // context graph (harmonic.context_graph): clip frames, evenly spread over
                                    // the range, whose pruned graphs join the calibration pose's in the
                                    // fixed topology (0 = calibration pose only); see harmonic_retarget.h
};

// The retargeted animation as GLB bytes, as RetargetJob::write_glb and the batch write it:
// props following their joints (opt.props_follow, glTF targets) and the export layout of `opt`.
// `report` (optional): the layout chosen, K, the measured error.
Status write_retarget_glb(const io::Asset& target, const AnimatedCharacter* target_character,
                          const RetargetJobOptions& opt, const std::string& clip_name,
                          const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                          std::vector<uint8_t>* bytes, io::MorphAnimationReport* report = nullptr);

// Every option of the retarget job; defaults from RetargetJobOptions / HarmonicRetargetOptions.
const OptionSchema<RetargetJobOptions>& retarget_options();

class RetargetJob {
 public:
  // source: a skinned, animated glTF. target: glTF or mesh. target_joints_json: {"name": [x,y,z]}
  // (required when the target has no skin; overrides its skin otherwise), or "auto": the source's
  // joints fitted inside the target (retarget/joint_fitting.h, default options). joint_map_json:
  // {"source joint": "target joint"} or "". Progress stages of the harmonic precompute.
  Status prepare(const io::Asset& source, const io::Asset& target, const std::string& target_joints_json,
                 const std::string& joint_map_json, const RetargetJobOptions& opt, const Progress& progress = {});

  int num_frames() const { return static_cast<int>(times_.size()); }
  const std::vector<double>& times() const { return times_; }  // seconds, clip time of each frame
  const std::string& clip_name() const { return clip_name_; }

  // Target surface (layout of target_rest) at frame k.
  Status frame(int k, Eigen::MatrixXd* V) const;
  // Frame k with the target joints f_t(J_t) (harmonic; empty for LBS).
  Status frame(int k, Eigen::MatrixXd* V, Eigen::MatrixXd* joints) const;
  // Frames [first, first + count), with progress per frame ("frames") and cancel. With `checks`,
  // also each frame's checks (the page plots them under its timeline).
  struct FrameChecks {
    std::vector<double> bone_length_error;  // harmonic: mean_b |ℓ_b(t) − ℓ_b| / ℓ_b of f_t(J_t); LBS: NaN
    std::vector<int> self_intersections;    // intersecting triangle pairs not already in the rest pose
  };
  Status frames(int first, int count, std::vector<Eigen::MatrixXd>* out, const Progress& progress = {},
                FrameChecks* checks = nullptr) const;
  // The source surface at frame k (for metrics: self-retargeting compares with it).
  Eigen::MatrixXd source_frame(int k) const;
  // Target joints at frame k (harmonic only: f_t(J_t) of the used joints), and bone data.
  const HarmonicRetargeter& harmonic() const { return harmonic_; }

  const Eigen::MatrixXd& target_rest() const { return target_V_; }
  const Eigen::MatrixXi& target_faces() const { return target_F_; }
  bool target_is_gltf() const { return target_is_gltf_; }
  const AnimatedCharacter& source_character() const { return source_; }
  const AnimatedCharacter* target_character() const { return target_is_gltf_ ? &target_ : nullptr; }
  const std::vector<std::string>& warnings() const { return warnings_; }

  // The context graph (harmonic method with harmonic.context_graph on; empty otherwise) as
  // overlay sets for viewing: source nodes, edges and one point set per body part (source
  // units), the compatible target nodes and edges, and the target's volume graph (target units).
  // The worker can return them as arrays or as bytes (debug_graph_glb).
  std::vector<io::DebugGeometry> context_graph_overlay() const;
  Status debug_graph_glb(std::vector<uint8_t>* bytes) const;

  // The animated target as GLB bytes (frames as from frames(), times relative to the first).
  Status write_glb(const std::vector<Eigen::MatrixXd>& frames, const std::vector<double>& times,
                   std::vector<uint8_t>* bytes, io::MorphAnimationReport* report = nullptr) const;

 private:
  RetargetJobOptions opt_;
  io::Asset target_asset_;
  AnimatedCharacter source_, target_;
  bool target_is_gltf_ = false;
  int clip_ = -1;
  std::string clip_name_;
  std::vector<double> times_;
  Eigen::MatrixXd target_V_;
  Eigen::MatrixXi target_F_;
  std::vector<std::string> warnings_;
  std::vector<std::pair<int, int>> rest_intersections_;  // pairs that intersect at rest (not counted per frame)
  HarmonicRetargeter harmonic_;
  // LBS baseline state.
  Similarity align_;
  SkinWeights lbs_weights_;
};

}  // namespace mm::app
