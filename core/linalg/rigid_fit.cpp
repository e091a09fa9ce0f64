#include "linalg/rigid_fit.h"

#include <algorithm>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace mm {

namespace rigid_fit_detail {

// The fit from the moments of centred (and, when weighted, √w-scaled) rows p̃, q̃:
// C = Σ q̃ p̃ᵀ, p2 = Σ |p̃|², q2 = Σ |q̃|², and the centroids.
RigidFit rigid_fit_from_moments(const Eigen::Matrix3d& C0, double p2, double q2, long rows,
                                const Eigen::RowVector3d& pc, const Eigen::RowVector3d& qc, const RigidFitOptions& opt) {
  RigidFit fit;
  fit.target_spread2 = q2;
  bool optimal = false;  // R is the unconstrained optimum (closed-form s and residual apply)
  double tr = 0;         // tr(ΣD)
  if (rows >= 3) {
    Eigen::Matrix3d C = C0;
    if (opt.rotation_prior > 0) C += opt.rotation_prior * p2 * Eigen::Matrix3d::Identity();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d sv = svd.singularValues();
    if (opt.min_spread < 0 || sv[1] > opt.min_spread * sv[0]) {
      Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
      if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1;
      fit.R = svd.matrixU() * D * svd.matrixV().transpose();
      tr = (sv.asDiagonal() * D).trace();
      optimal = !opt.snap_to_axes;
      if (opt.snap_to_axes) fit.R = nearest_axis_rotation(fit.R);
    } else {
      fit.degenerate = true;
    }
  } else {
    fit.degenerate = true;
  }
  if (optimal) {
    // Umeyama: s = tr(ΣD)/Σ|p̃|², residual = Σ|q̃|² − tr²/Σ|p̃|² (scaled) or Σ|p̃|² + Σ|q̃|² − 2tr.
    if (opt.scale) {
      fit.s = p2 > 0 ? tr / p2 : 1.0;
      fit.residual2 = p2 > 0 ? std::max(0.0, q2 - tr * tr / p2) : q2;
    } else {
      fit.residual2 = std::max(0.0, p2 + q2 - 2 * tr);
    }
  } else {
    // R fixed (snapped, or I when degenerate): least-squares s = Σ (R p̃)·q̃ / Σ |R p̃|², where
    // Σ (R p̃)·q̃ = tr(R Cᵀ) and |R p̃| = |p̃|.
    const double rc = fit.R.cwiseProduct(C0).sum();
    if (opt.scale) fit.s = p2 > 0 ? rc / p2 : 1.0;
    fit.residual2 = std::max(0.0, fit.s * fit.s * p2 - 2 * fit.s * rc + q2);
  }
  fit.t = (qc - fit.s * pc * fit.R.transpose()).transpose();
  return fit;
}

RigidFit rigid_fit_centred(const Eigen::MatrixXd& P0, const Eigen::MatrixXd& Q0, const Eigen::RowVector3d& pc,
                           const Eigen::RowVector3d& qc, const RigidFitOptions& opt) {
  const Eigen::Matrix3d C = Q0.transpose() * P0;  // Σ w (q − q̄)(p − p̄)ᵀ
  return rigid_fit_from_moments(C, P0.squaredNorm(), Q0.squaredNorm(), P0.rows(), pc, qc, opt);
}

}  // namespace rigid_fit_detail

RigidFit fit_rigid(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q, const RigidFitOptions& options) {
  const Eigen::RowVector3d pc = P.colwise().mean(), qc = Q.colwise().mean();
  const Eigen::MatrixXd P0 = P.rowwise() - pc, Q0 = Q.rowwise() - qc;
  return rigid_fit_detail::rigid_fit_centred(P0, Q0, pc, qc, options);
}

RigidFit fit_rigid(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q, const Eigen::VectorXd& w,
                   const RigidFitOptions& options) {
  const double total = w.sum();
  const Eigen::RowVector3d pc = (w.transpose() * P) / total, qc = (w.transpose() * Q) / total;
  const Eigen::VectorXd sw = w.cwiseMax(0.0).cwiseSqrt();
  const Eigen::MatrixXd P0 = sw.asDiagonal() * (P.rowwise() - pc).eval();
  const Eigen::MatrixXd Q0 = sw.asDiagonal() * (Q.rowwise() - qc).eval();
  return rigid_fit_detail::rigid_fit_centred(P0, Q0, pc, qc, options);
}

RigidFitFromRest::RigidFitFromRest(const Eigen::MatrixXd& P, const std::vector<int>& rows, const Eigen::VectorXd& w,
                                   const RigidFitOptions& options)
    : rows_(rows), w_(w.cwiseMax(0.0)), opt_(options) {
  const long n = static_cast<long>(rows_.size());
  total_ = w.sum();
  pc_.setZero();
  if (n == 0 || !(total_ > 0)) return;
  for (long k = 0; k < n; ++k) pc_ += w[k] * P.row(rows_[k]);
  pc_ /= total_;
  Pw_.resize(3, n);
  p2_ = 0;
  for (long k = 0; k < n; ++k) {
    const Eigen::Vector3d d = (P.row(rows_[k]) - pc_).transpose();
    Pw_.col(k) = w_[k] * d;
    p2_ += w_[k] * d.squaredNorm();
  }
}

RigidFit RigidFitFromRest::fit(const Eigen::MatrixXd& X) const {
  const long n = static_cast<long>(rows_.size());
  Eigen::RowVector3d qc = Eigen::RowVector3d::Zero();
  if (n == 0 || !(total_ > 0)) return rigid_fit_detail::rigid_fit_from_moments(Eigen::Matrix3d::Zero(), 0, 0, n, pc_, qc, opt_);
  for (long k = 0; k < n; ++k) qc += w_[k] * X.row(rows_[k]);
  qc /= total_;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  double q2 = 0;
  for (long k = 0; k < n; ++k) {
    const Eigen::Vector3d q = (X.row(rows_[k]) - qc).transpose();
    C.noalias() += q * Pw_.col(k).transpose();  // Σ w (q − q̄)(p − p̄)ᵀ
    q2 += w_[k] * q.squaredNorm();
  }
  return rigid_fit_detail::rigid_fit_from_moments(C, p2_, q2, n, pc_, qc, opt_);
}

Eigen::Matrix3d nearest_axis_rotation(const Eigen::Matrix3d& R) {
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  double best_score = -1e300;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) C(r, p[r]) = (signs >> r & 1) ? -1.0 : 1.0;
      if (C.determinant() < 0) continue;
      const double score = (C.transpose() * R).trace();
      if (score > best_score + 1e-12) {
        best_score = score;
        best = C;
      }
    }
  return best;
}

}  // namespace mm
