// harmonic_retarget: motion retargeting by harmonic maps (paper 002, Liu et al. MIG 2018,
// Sec. 3–5, 7). A session: precompute once per (source, target) pair, then one cheap call per
// source frame.
//
// Analysis (Sec. 4): the source calibration surface gets an MFS harmonic map
// (retarget/harmonic_map.h); each source frame is fitted, Ws = As⁺ bs (Eq. 13), and its
// Jacobians are read at descriptor points, Jsᵀ = Ds Ws (Eq. 4, 14).
// Synthesis (Sec. 5, 7.2): the target's coefficients Wt minimise (retarget/harmonic_synthesis.h)
//   w_affine   Σ_d ‖Dt(x_d) Wt − Js(x_d)ᵀ‖² / #d                 E_affine, Eq. 5
//   w_position ‖Kt(a) Wt − p(t)‖²                                 E_position, Eq. 8
//   w_bone     Σ_b ‖(Kt(c_b) − Kt(p_b)) Wt / l_b − d̂_b‖² / #b     E_bone, Eq. 9–10 linearised
//   w_smooth   Σ_h ‖Hessian(Kt Wt)(y_h)‖² / #h                    E_smooth, Eq. 7
// and the target pose is V = Kt Wt for every target vertex (Eq. 6).
//
// Choices where the paper is silent or self-contradictory (each documented at its option):
// - Units: both shapes are centred and scaled to a unit bounding-box diagonal; the target is
//   rotated into the source's axes (rest poses matched by joints, rotation snapped to the 24
//   axis-aligned ones, so Z-up and Y-up files combine). Energies are means, so weights do not
//   depend on sample counts.
// - Weights (Sec. 7.2 lists 0.01, 10, 1, 0.8, 1 for position, smooth, bone, spatial, volume,
//   while its text says position must be large and smoothness small): we follow the text and
//   read the list as smooth small, position = 10 (tests compare both readings); smooth = 0.001
//   rather than the list's 0.01 because it lowered every measured error (docs/retarget.md).
// - Position (Eq. 8, "any point, e.g. v1"): the anchor is a joint (default: the shallowest
//   used joint in the source hierarchy, i.e. the hips/root), and its trajectory is the source
//   anchor's displacement f_s(a_s) − a_s scaled by the ratio of anchor heights above the
//   lowest vertex (leg-length ratio), added to the target anchor's rest position.
// - Bone (Eq. 9): linearised by fixing each bone's direction d̂_b at the previous iterate, so the
//   matrix stays constant (factored once) and re-linearising only changes B. The first
//   direction is the rest bone mapped by the mean source Jacobian of its two ends.
// - Descriptor points: the joints (paper) plus `bone_samples` points inside each bone and
//   `surface_descriptors` points on the target surface whose source points come from bone
//   coordinates (retarget/bone_correspondence.h). With joints only, the map away from the
//   skeleton is left to E_smooth and self-retargeting errors reach 2–20% of the size (the
//   paper's Table 1 reports 0.021–0.193); with surface descriptors they drop below 1%.
//
// Joints: matched by name or map (retarget/joint_set.h). A source joint outside its surface is
// dropped with a warning (skeletons often have a root on the floor); a target joint outside
// its surface is an error when the joints were placed by the user, else dropped.
#pragma once

#include <map>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/progress.h"
#include "common/status.h"
#include "linalg/rigid_fit.h"
#include "retarget/bone_blend.h"
#include "retarget/context_graph.h"
#include "retarget/harmonic_map.h"
#include "retarget/harmonic_synthesis.h"
#include "retarget/nonrigid_icp.h"
#include "character/joint_set.h"
#include "character/skinning.h"

namespace mm {

// One side of the retargeting at its calibration (rest) pose.
struct RetargetCharacter {
  Eigen::MatrixXd V;  // #V by 3 calibration surface (any triangle soup: parts, open, non-manifold)
  Eigen::MatrixXi F;  // #F by 3
  JointSet joints;    // calibration joints; the source's hierarchy (parent) defines the bones
  // Optional skin of the surface over `joints` (#V by K indices into joints, weights; a glTF
  // source's own skin, rigid parts at weight 1 on their joint). The articulated base then takes
  // its bone weights from it instead of learning them from poses. Empty: learned / by distance.
  SkinWeights skin;
};

struct HarmonicRetargetOptions {
  HarmonicMapOptions map;       // MFS of both calibration shapes (singularities, collocation, SVD)
  double w_affine = 1.0;        // λ_affine: Jacobian match at descriptor points (reference weight)
  double w_position = 10.0;     // λ_position: anchor trajectory; "should be with a large weight"
  double w_smooth = 0.001;      // λ_smooth: Hessian energy; "should be small, otherwise flattened".
                                // The list's 0.01 was our first default; 0.001 lowered every measured
                                // error (self-retargeting, Knight → Barbarian, Fox bone lengths) and
                                // still keeps λ_smooth = 10 apart as flattening (docs/retarget.md)
  double w_bone = 1.0;          // λ_bone: bone-length preservation
  int bone_iterations = 2;      // re-linearisations of E_bone after the first solve (0 = one solve)
  int bone_samples = 1;         // descriptor points inside each bone besides its ends (0 = joints only, as in the paper)
  int surface_descriptors = 400;// target surface points that also get an affine descriptor, their source
                                // point found in bone coordinates (0 = joints only, as in the paper)
  int num_smooth_points = 600;  // target surface points where E_smooth is evaluated (FPS subset)
  double ridge = 1e-9;          // Tikhonov ridge on the normal matrix, × its mean diagonal
  std::string anchor_joint;     // joint for E_position (a source joint name); "" = shallowest used joint
  int up_axis = 1;              // source up axis (0 x, 1 y, 2 z) for anchor heights; glTF is +Y
  bool align_axes = true;       // rotate the target into the source's axes (snapped Kabsch on joints)
  double joint_tolerance = 0.01;// joints within this × bbox diagonal outside the surface count as inside

  // Articulated base (not in the paper; docs/retarget.md "Articulated base"): each source frame's
  // bones get a rigid motion (least-squares fit of the source vertices each bone dominates), the
  // target's bones the same rotations by forward kinematics from its own rest joints and the
  // anchor trajectory, and both surfaces follow them by per-vertex bone weights (the source's
  // skin, or learned; carried to the target by the bone-posed closest point; bone_blend.h). Leaf
  // joints get bones of their own (a head, a hand, a foot under an IK root).
  // The MFS maps then carry only the residual — the fit's floor (0.011 of the height with 260
  // singularities on KayKit's rigid parts) no longer applies to the articulated motion. With
  // the context graph, E_spatial asks the maps for what the base leaves at the graph nodes and
  // E_volume (weight w_volume_base) only damps their residual. Every step is continuous in the input (weights, fits, correspondences), so native
  // and wasm agree.
  bool articulated_base = true;
  // The base's bone weights: from the source's own skin (RetargetCharacter::skin) when given and
  // this is on; otherwise learned from the base frames (or by distance without them).
  bool base_skin_weights = true;
  // The target's base weights from its own skin (RetargetCharacter::skin of the target, over its
  // joints) when given and this is on; vertices it does not cover take the source's weights at
  // their counterparts.
  bool base_target_skin = true;
  // Carried-over target weights diffused over the target surface across about this × its bbox
  // diagonal (smooth_blend), so that joints blend like a skin rather than cut like rigid parts
  // (a KayKit source's rigid weights): Knight → woman new self-intersecting pairs per frame 836 →
  // 52, CesiumMan → woman 227 → 50 (docs/retarget.md). 0 = off.
  double base_target_smoothing = 0.03;
  double base_fit_weight = 0.3;     // a source vertex joins a bone's rigid fit from this weight on (weighed by w²)
  int base_frames = 16;             // source poses the job hands over for learning the weights (spread over all clips)

  // Context graph (paper Sec. 6, Eq. 11–12; see "Context graph" above precompute()).
  bool context_graph = false;   // add E_spatial and E_volume (docs/retarget.md: measured, off by default)
  ContextGraphOptions graph;    // body parts and pruning rules (Sec. 6.1)
  double w_spatial = 0.8;       // λ_spatial (Sec. 7.2 list: 0.8)
  double w_volume = 1.0;        // λ_volume (Sec. 7.2 list: 1)
  double w_volume_base = 0.0;   // λ_volume with the articulated base, which moves the volume graph bone by
                                // bone already; E_volume then only damps the residual there (measured with
                                // 1: CesiumMan self 0.0022 vs 0.0007, Sit_Floor_Idle contacts 0.83 vs 1.0)
  int icp_points = 800;         // non-rigid ICP template: the graph nodes plus FPS source vertices up to this
  int icp_neighbours = 6;       // k of the template's k-nearest-neighbour stiffness graph
  bool icp_bone_start = true;   // start the ICP template posed by the bones (articulated_points)
  NonrigidIcpOptions icp;       // Amberg et al. 2007 schedule and convergence criteria
  int volume_surface_points = 300;  // target surface nodes of the volume graph (FPS collocation prefix)
  int volume_bone_samples = 3;      // interior nodes per bone besides its ends
  int volume_neighbours = 3;        // interior nodes each surface node connects to (visible ones)
};

// The Context Graph as built by precompute (working frames mapped back to each side's units).
struct ContextGraphInfo {
  Eigen::MatrixXd source_nodes;         // #N by 3 nodes on the source calibration surface
  Eigen::MatrixXd target_nodes;         // #N by 3 compatible nodes on the target calibration surface
  Eigen::VectorXi target_face;          // #N target triangle of each target node
  Eigen::MatrixXd target_barycentric;   // #N by 3 its weights (evaluate the nodes on any target frame)
  std::vector<std::pair<int, int>> edges;  // fixed topology (union over calibration + graph frames)
  std::vector<std::pair<int, int>> calibration_edges;  // pruned graph of the calibration pose alone
  Eigen::VectorXi part;                 // #N body part of each node (index into used joints)
  Eigen::VectorXi vertex_part;          // #V_source body part of each source vertex
  PruneCounts counts;                   // rule counts at the calibration pose
  bool icp_converged = false;           // false: target nodes from the fallback (see warnings)
  double icp_residual = 0;              // mean ICP template-to-target distance / target diagonal
  Eigen::MatrixXd volume_nodes;         // #Nv by 3 volume graph nodes (target units): surface then interior
  std::vector<std::pair<int, int>> volume_edges;
  int volume_surface = 0;               // the first volume_surface rows of volume_nodes are on the surface
};

struct RetargetFrame {
  Status status;              // NumericalError if the synthesis produced non-finite values
  Eigen::MatrixXd V;          // #V_target by 3 target positions (target units and axes)
  Eigen::MatrixXd joints;     // #used joints by 3 target joint positions f_t(J_t)
  Eigen::MatrixXd source_joints;  // #used joints by 3 source joints mapped by the fit f_s(J_s)
  double fit_residual = 0;    // RMS collocation residual of the source fit / source bbox diagonal
  Eigen::MatrixXd graph_nodes;  // #N by 3 target context-graph nodes f_t(Va) (empty without the graph)
};

class HarmonicRetargeter {
 public:
  // Samples both MFS bases, factors As (SVD) and the synthesis normal matrix. Progress stages:
  // "source map", "target map", "synthesis".
  Status precompute(const RetargetCharacter& source, const RetargetCharacter& target,
                    const std::map<std::string, std::string>& source_to_target = {},
                    const HarmonicRetargetOptions& opt = {}, const Progress& progress = {});

  // Context graph topology (Sec. 6): the paper rebuilds the pruned graph on every deformed source
  // pose, which would change E_spatial's matrix and the factored normal matrix per frame. Here the
  // topology is fixed at precompute — the union of the pruned graphs of the calibration pose and
  // of these source frames (same layout as source.V; e.g. samples of the clip) — and only the node
  // positions change per frame. Call before precompute; empty = the calibration pose only.
  void set_graph_frames(std::vector<Eigen::MatrixXd> frames) { graph_frames_ = std::move(frames); }
  // Articulated base: source frames (same layout as source.V; e.g. samples of the clip) from
  // which each source vertex's bone weights are learned. Call before precompute; empty = weights
  // by distance to the bones on both sides.
  void set_base_frames(std::vector<Eigen::MatrixXd> frames) { base_frames_ = std::move(frames); }

  // Target pose for one source frame V_source (same layout as source.V).
  RetargetFrame retarget(const Eigen::MatrixXd& V_source) const;

  bool ready() const { return ready_; }
  // Used joint pairs (indices into source/target JointSets) in the order of RetargetFrame::joints.
  const std::vector<JointPair>& used_joints() const { return used_; }
  // Bones as (child, parent) indices into used_joints().
  const std::vector<std::pair<int, int>>& bones() const { return bones_; }
  const Eigen::VectorXd& rest_bone_lengths() const { return rest_len_world_; }  // target units
  int anchor() const { return anchor_; }                        // index into used_joints()
  const Eigen::Matrix3d& alignment() const { return R_; }       // target axes → source axes
  double anchor_scale() const { return scale_; }                // root-motion scale (target/source)
  int num_descriptor_points() const { return static_cast<int>(Xs_desc_.rows()); }
  // Descriptor points (working frames: centred, unit bbox diagonal, target rotated) on both sides.
  const Eigen::MatrixXd& source_descriptors() const { return Xs_desc_; }
  const Eigen::MatrixXd& target_descriptors() const { return Xt_desc_; }
  const MfsHarmonicMap& source_map() const { return src_map_; }
  const MfsHarmonicMap& target_map() const { return tgt_map_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  bool has_context_graph() const { return graph_on_; }
  const ContextGraphInfo& context_graph() const { return graph_; }
  // Source graph nodes on a source frame (same layout as source.V), source units.
  Eigen::MatrixXd source_graph_nodes(const Eigen::MatrixXd& V_source) const;

 private:
  Status build_context_graph(const Eigen::MatrixXd& Xs, const Eigen::MatrixXi& Fs, const Eigen::MatrixXd& Xt,
                             const Eigen::MatrixXi& Ft, const TriangleBvh& bvh_s, const TriangleBvh& bvh_t,
                             const HarmonicRetargetOptions& opt);

  // Articulated base: bone motions of a source frame (working frame), and the target joints they
  // give by forward kinematics (rows of used joints) with the target bones' motions.
  BoneMotions source_bone_motions(const Eigen::MatrixXd& Xs) const;
  // base_bones_ (the used bones, plus leaf bones when asked) and their rest joints on both sides.
  void build_base_skeleton(const Eigen::MatrixXd& Xs, bool leaf_bones);
  // The base's motions of a source frame: rigid fits, joints where they meet, bones turned onto
  // those joints (rotations R), FK from the roots (joints Js_base).
  BoneMotions source_base(const Eigen::MatrixXd& Xs, Eigen::MatrixXd* Js_base, std::vector<Eigen::Matrix3d>* R) const;
  // J: rows of roots set on entry; the other joints follow their bones' rotations R from the rest
  // joints J_rest. Returns the bones' motions (R, translations) that map J_rest to J.
  BoneMotions forward_kinematics(const std::vector<Eigen::Matrix3d>& R, const Eigen::MatrixXd& J_rest,
                                 Eigen::MatrixXd* J) const;

  bool ready_ = false;
  HarmonicRetargetOptions opt_;
  std::vector<std::string> warnings_;
  std::vector<JointPair> used_;
  std::vector<std::pair<int, int>> bones_;
  int anchor_ = 0;
  double scale_ = 1;
  // Working frames: x_s' = (x − cs)/Ls, x_t' = R (x − ct)/Lt.
  Eigen::RowVector3d cs_, ct_;
  double Ls_ = 1, Lt_ = 1;
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  MfsHarmonicMap src_map_, tgt_map_;
  Eigen::MatrixXd Xs_desc_, Xt_desc_;   // descriptor points (working frames)
  Eigen::MatrixXd Ks_joints_;           // #used by N_a(source)
  Eigen::MatrixXd Kt_joints_;           // #used by N_a(target)
  // Per-frame operators (see precompute): r = rank of the source's As.
  Eigen::MatrixXd KsJ_;                 // #used by r: source joints from Ys
  Eigen::MatrixXd GT_;                  // [Ga gp Gb]ᵀ: r + 1 + #bones by N_a(target)
  Eigen::MatrixXd KtGa_, Ktgp_, KtGb_;  // the same mapped to the target joints
  Eigen::MatrixXd KtT_all_;             // N_a(target) by #V_target: Ktᵀ (see transposed_times_n3)
  Eigen::MatrixXd Js_rest_, Jt_rest_;   // used joints, working frames
  std::vector<std::pair<int, int>> bone_desc_;  // descriptor indices of each bone's ends
  Eigen::VectorXd rest_len_;            // target bone lengths, working units
  Eigen::VectorXd rest_len_world_;
  HarmonicSynthesis synth_;
  int term_affine_ = -1, term_position_ = -1, term_bone_ = -1;
  // Articulated base.
  bool base_on_ = false;
  std::vector<Eigen::MatrixXd> base_frames_;
  Eigen::MatrixXd Xt_rest_, colloc_rest_s_;          // working frames
  std::vector<RigidFitFromRest> base_fits_;           // per bone: the rigid fit of its source vertices
  BoneBlend blend_colloc_s_, blend_verts_t_;
  std::vector<std::pair<int, int>> base_bones_;       // bones_, then leaf bones (joint → tip)
  Eigen::MatrixXd base_Js_rest_, base_Jt_rest_;       // used joints, then the leaf bones' tips (working)
  std::vector<int> fk_bones_;                          // base_bones_ indices, parents before children
  std::vector<int> joint_root_;                        // per used joint: the root of its tree
  // Context graph (Sec. 6).
  std::vector<Eigen::MatrixXd> graph_frames_;
  bool graph_on_ = false;
  ContextGraphInfo graph_;
  SurfaceNodes src_nodes_;              // on the source calibration surface (working frame)
  Eigen::MatrixXi src_F_;
  int term_spatial_ = -1, term_volume_ = -1;
  Eigen::SparseMatrix<double> Lsp_;     // rows of the graph Laplacian with degree > 0 (#rows by #N)
  Eigen::MatrixXd Va_;                  // target nodes (working)
  Eigen::MatrixXd sp_corr_;             // #rows by 3: L Va − s L Pa_rest (rotated per frame)
  Eigen::VectorXi sp_bone_;             // #rows bone whose rotation turns sp_corr_ (-1: none)
  Eigen::MatrixXd Gsp_pos_, Gsp_corr_;  // N_a by #N, N_a by #rows
  Eigen::MatrixXd vol_delta_;           // #rows_v by 3 rest Laplacian coordinates of the volume graph
  BoneBlend blend_Va_;                  // articulated base at the target nodes
  Eigen::VectorXi vol_bone_;            // #rows_v
  Eigen::MatrixXd Gvol_;                // N_a by #rows_v
  Eigen::MatrixXd DmidVS_;              // 3·#bones by r: source Jacobians at bone midpoints from Ys
  Eigen::MatrixXd KtVa_;                // #N by N_a
  double graph_scale_ = 1;              // s: target / source height (working units)
  double graph_sp_len_ = 1, graph_vol_len_ = 1;  // ℓ, ℓ_v: mean edge lengths (rows divided by them)
};

}  // namespace mm
