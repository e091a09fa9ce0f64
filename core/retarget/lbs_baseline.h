// Baseline for comparison (paper 002 Fig. 6 f): "naive" linear blend skinning of the target with
// the source's skin weights, transferred by closest point after aligning the rest poses.
//
// Naive on purpose: the target is driven by the source's joint transforms, so a target whose
// joints sit elsewhere (other proportions) twists and interpenetrates — the artefact the paper
// shows. Same rig and proportions (Knight → Barbarian) make it a strong baseline.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "character/joint_set.h"
#include "character/skinning.h"

namespace mm {

// A similarity x_s = s·R·x_t + t mapping target rest space onto source rest space.
struct Similarity {
  double s = 1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix4d matrix() const;          // as a 4x4 homogeneous transform
  Eigen::MatrixXd apply(const Eigen::MatrixXd& X) const;  // rows
};

// Rest-pose alignment from matched joint positions: rotation = Kabsch snapped to the 24
// axis-aligned rotations (as in harmonic_retarget.h), then scale and translation by least squares.
// With fewer than 3 pairs only scale (bbox diagonals) and centroid are matched.
Similarity align_rest_poses(const JointSet& source, const JointSet& target, const std::vector<JointPair>& pairs,
                            const Eigen::MatrixXd& V_source, const Eigen::MatrixXd& V_target);

struct SkinTransferResult {
  Status status;        // InvalidMesh when the source surface is empty
  SkinWeights weights;  // #V_target by K
};

// Skin weights of target points (already in the source rest space) from the closest point on
// the source rest surface: barycentric blend of its triangle's corner influences, the K largest
// kept and renormalised.
SkinTransferResult transfer_skin_weights(const Eigen::MatrixXd& V_source, const Eigen::MatrixXi& F_source,
                                         const SkinWeights& source_weights, const Eigen::MatrixXd& V_target_aligned,
                                         int K = 4);

// The baseline pose: target rest positions (target space) skinned with transferred weights by
// the source's transforms M (source space), mapped back: x' = A⁻¹ LBS(A x).
Eigen::MatrixXd lbs_retarget(const Eigen::MatrixXd& V_target, const Similarity& A, const SkinWeights& W,
                             const Matrix4dList& M_source);

}  // namespace mm
