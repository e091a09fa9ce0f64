// bone_blend: points moved by the rigid motions of nearby bones, blended (a skinning without a
// rig: the weights come from distances to the bone segments). Used to pose the non-rigid ICP's
// template (articulated_points) and as the articulated base of the harmonic retargeting
// (HarmonicRetargetOptions::articulated_base), where the MFS map then carries only what the bones
// do not.
//
// Weights: d_b = distance of the point to bone b's segment, d = min_b d_b; bones with d_b < 2d get
// w_b ∝ d_b⁻⁴ − (2d)⁻⁴ (continuous in the point: a bone's weight reaches 0 where it leaves the
// 2d band), at most kMaxBones per point, normalised. A point on a joint (d_b = 0 for the bones
// meeting there) takes only those bones.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace mm {

// Sparse rows: point i blends bones bone[ptr[i] .. ptr[i+1]) with weights w (sum 1).
struct BoneBlend {
  static constexpr int kMaxBones = 4;
  std::vector<int> ptr{0}, bone;
  std::vector<double> w;
  int rows() const { return static_cast<int>(ptr.size()) - 1; }
  // The bone of largest weight and that weight (-1, 0 for a point without bones).
  std::pair<int, double> dominant(int i) const;
};

// bones: (child, parent) rows of J. Points get no bones when `bones` is empty or degenerate.
// band: bones within band × the nearest bone's distance take part (2 for weights; wider to list
// candidates for learn_bone_weights).
BoneBlend bone_blend(const Eigen::MatrixXd& P, const Eigen::MatrixXd& J, const std::vector<std::pair<int, int>>& bones,
                     double band = 2.0);

// One rigid motion per bone: x' = R x + t.
struct BoneMotions {
  std::vector<Eigen::Matrix3d> R;
  Eigen::MatrixXd t;  // #bones by 3
};

// Y_i = Σ_b w_ib (R_b P_i + t_b); rows without bones are copied.
Eigen::MatrixXd apply_bone_motions(const BoneBlend& blend, const Eigen::MatrixXd& P, const BoneMotions& m);

// Weights that explain observed motion: for each point i, the convex weights over its candidate
// bones (the rows of `candidates`) minimising Σ_f ‖Σ_b w_b (R_b^f X_i + t_b^f) − Y_f,i‖² over the
// sample frames Y_f (same rows as X) with the bones' motions M_f, plus a small pull (1e-4 of the
// data term's scale) towards the candidates' own weights so that bones that move alike share.
BoneBlend learn_bone_weights(const Eigen::MatrixXd& X, const std::vector<Eigen::MatrixXd>& Y,
                             const std::vector<BoneMotions>& M, const BoneBlend& candidates);

// Weights at points on a surface (triangle `face[i]` of F with barycentric weights `bary.row(i)`)
// from per-vertex weights W: the corners' weights mixed, the kMaxBones largest kept, normalised.
// Points with face < 0 take the row of `fallback` (none when it is null).
BoneBlend interpolate_blend(const BoneBlend& W, const Eigen::MatrixXi& F, const Eigen::VectorXi& face,
                            const Eigen::MatrixXd& bary, const BoneBlend* fallback = nullptr);

// Weights from a skin: point i's weight weight(i, k) on skin joint index(i, k) goes to the bones
// that joint drives (drives[joint]: bone indices; empty = the weight is dropped), split among them
// by the inverse fourth power of the point's distance to their segments (continuous in the point).
// Beyond kMaxBones the next weight is subtracted from the kept ones. Rows that keep less than half
// of their weight take the row of `fallback`.
BoneBlend skin_blend(const Eigen::MatrixXd& P, const Eigen::MatrixXi& index, const Eigen::MatrixXd& weight,
                     const std::vector<std::vector<int>>& drives, const Eigen::MatrixXd& J,
                     const std::vector<std::pair<int, int>>& bones, const BoneBlend& fallback);

// Weights diffused over a surface (V, F): W' = (I + (σ/ℓ)² L)⁻¹ W per bone, with L the graph
// Laplacian of the mesh's edges and ℓ its mean edge length, so the blend zone spans about σ in
// length units; separate components stay separate. nb: number of bones. Rows re-cut to
// kMaxBones (the next weight subtracted). σ ≤ 0 returns W.
BoneBlend smooth_blend(const BoneBlend& W, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, int nb, double sigma);

// A start for templates far from the target's pose (e.g. a rest pose onto a walk frame, where
// closest points pull a swung arm onto the body and the stiff first ICP steps never let go): each
// bone turns by the smallest rotation taking J0(child) − J0(parent) onto J1(child) − J1(parent)
// (no twist), about its parent end, carried to J1(parent); the points blend these motions.
Eigen::MatrixXd articulated_points(const Eigen::MatrixXd& P, const Eigen::MatrixXd& J0, const Eigen::MatrixXd& J1,
                                   const std::vector<std::pair<int, int>>& bones);

}  // namespace mm
