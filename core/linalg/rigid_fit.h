// Best-fit rigid motion or similarity between two corresponding point sets (rows of P and Q):
// Kabsch (rotation + translation) or Umeyama 1991 (with a uniform scale), optionally
// weighted, optionally snapped to the nearest of the 24 axis-aligned rotations.
//
// The fit maps P onto Q: q ≈ s·R·p + t. With C = Σ wᵢ (qᵢ − q̄)(pᵢ − p̄)ᵀ = UΣVᵀ,
// R = U·D·Vᵀ with D = diag(1, 1, det(UVᵀ)) (a proper rotation), s = tr(ΣD) / Σ wᵢ|pᵢ − p̄|²,
// t = q̄ − s·R·p̄. R is the rotation of polar_decomposition(C) (linalg/polar.h), bit for bit.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mm {

struct RigidFitOptions {
  bool scale = false;          // fit a uniform scale s (similarity, Umeyama); otherwise s = 1 (Kabsch)
  bool snap_to_axes = false;   // replace R by the nearest (max tr(CᵀR)) of the 24 axis-aligned rotations
  // No rotation can be read off (degenerate) when there are fewer than 3 points or when
  // σ₂ ≤ min_spread·σ₁ (collinear points). Negative: only the point count is checked.
  double min_spread = -1;
  // Adds this × Σw|p̃|² × I to the cross-covariance: a pull towards no rotation that decides the
  // rotation about a degenerate axis (thin or flat point sets) instead of rounding noise. 0 = off.
  double rotation_prior = 0;
};

struct RigidFit {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // proper rotation, P → Q
  double s = 1;                                      // uniform scale (1 unless options.scale)
  Eigen::Vector3d t = Eigen::Vector3d::Zero();       // q ≈ s·R·p + t
  // Σ wᵢ|s·R·(pᵢ − p̄) − (qᵢ − q̄)|² of the returned fit (≥ 0), and Σ wᵢ|qᵢ − q̄|².
  double residual2 = 0;
  double target_spread2 = 0;
  // True when no rotation could be read off: R = I, and (with options.scale) s is the
  // least-squares scale for R = I, as for a snapped rotation.
  bool degenerate = false;
};

// P, Q: n by 3, corresponding rows. Without weights every row counts once.
RigidFit fit_rigid(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q, const RigidFitOptions& options = {});

// Weighted: w (n, ≥ 0, not all zero) weighs each correspondence (centroids are weighted too).
RigidFit fit_rigid(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q, const Eigen::VectorXd& w,
                   const RigidFitOptions& options = {});

// The weighted fit of fixed rest points onto targets that change from call to call (a bone's
// vertices in each frame of a clip): what depends on the rest points and weights alone (their
// centroid, the weighted centred rows, Σw|p̃|²) is computed once, and each fit is two passes over
// the targets and a 3×3 SVD, without allocating. The same fit as fit_rigid(P(rows), X(rows), w)
// to rounding.
class RigidFitFromRest {
 public:
  RigidFitFromRest() = default;
  // The rest points are P's rows `rows`, weighed by w (one per row, ≥ 0).
  RigidFitFromRest(const Eigen::MatrixXd& P, const std::vector<int>& rows, const Eigen::VectorXd& w,
                   const RigidFitOptions& options);
  // The fit onto X's rows `rows` (X has P's shape). Degenerate without points or weight.
  RigidFit fit(const Eigen::MatrixXd& X) const;
  int size() const { return static_cast<int>(rows_.size()); }
  double total_weight() const { return total_; }

 private:
  std::vector<int> rows_;
  Eigen::VectorXd w_;
  Eigen::Matrix<double, 3, Eigen::Dynamic> Pw_;  // w (p − p̄), one column per point
  Eigen::RowVector3d pc_ = Eigen::RowVector3d::Zero();
  double total_ = 0, p2_ = 0;
  RigidFitOptions opt_;
};

// The axis-aligned rotation (one of 24: signed permutation matrices with det +1) nearest to R,
// i.e. maximising tr(CᵀR); ties go to the first in a fixed order (identity first).
Eigen::Matrix3d nearest_axis_rotation(const Eigen::Matrix3d& R);

}  // namespace mm
