#include "retarget/nonrigid_icp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "mesh/mesh.h"

namespace mm {

std::vector<std::pair<int, int>> knn_edges(const Eigen::MatrixXd& P, int k) {
  const int n = static_cast<int>(P.rows());
  std::vector<std::pair<int, int>> e;
  std::vector<std::pair<double, int>> d(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) d[j] = {(P.row(i) - P.row(j)).squaredNorm(), j};
    const int kk = std::min(k + 1, n);
    std::partial_sort(d.begin(), d.begin() + kk, d.end());
    for (int a = 0; a < kk; ++a)
      if (d[a].second != i) e.push_back({std::min(i, d[a].second), std::max(i, d[a].second)});
  }
  std::sort(e.begin(), e.end());
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

std::vector<std::pair<int, int>> triangle_edges(const Eigen::MatrixXi& F) {
  std::vector<std::pair<int, int>> e;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int a = F(f, c), b = F(f, (c + 1) % 3);
      if (a != b) e.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(e.begin(), e.end());
  e.erase(std::unique(e.begin(), e.end()), e.end());
  return e;
}

NonrigidIcpResult nonrigid_icp(const Eigen::MatrixXd& P, const std::vector<std::pair<int, int>>& edges,
                               const TriangleBvh& target, const Eigen::VectorXi& landmark_vertex,
                               const Eigen::MatrixXd& landmark_point, const Eigen::MatrixXd& landmark_target,
                               const NonrigidIcpOptions& opt) {
  using SpMat = Eigen::SparseMatrix<double>;
  NonrigidIcpResult out;
  const int n = static_cast<int>(P.rows());
  const int nl = static_cast<int>(landmark_vertex.size());
  const double diag = bounding_box_diagonal(target.V());
  const double max_d2 = std::pow(opt.max_distance * diag, 2);
  // Stiffness part (M ⊗ G)ᵀ(M ⊗ G) and the landmark part: fixed for the whole run.
  std::vector<Eigen::Triplet<double>> t;
  const double g2[4] = {1, 1, 1, opt.gamma * opt.gamma};
  for (const auto& [i, j] : edges)
    for (int c = 0; c < 4; ++c) {
      t.emplace_back(4 * i + c, 4 * i + c, g2[c]);
      t.emplace_back(4 * j + c, 4 * j + c, g2[c]);
      t.emplace_back(4 * i + c, 4 * j + c, -g2[c]);
      t.emplace_back(4 * j + c, 4 * i + c, -g2[c]);
    }
  SpMat S(4 * n, 4 * n);
  S.setFromTriplets(t.begin(), t.end());
  t.clear();
  Eigen::MatrixXd BL = Eigen::MatrixXd::Zero(4 * n, 3);  // landmark right-hand side Dₗᵀ T
  for (int l = 0; l < nl; ++l) {
    const int k = landmark_vertex[l];
    Eigen::Vector4d d;
    d << landmark_point.row(l).transpose(), 1.0;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) t.emplace_back(4 * k + a, 4 * k + b, d[a] * d[b]);
      BL.row(4 * k + a) += d[a] * landmark_target.row(l);
    }
  }
  SpMat SL(4 * n, 4 * n);
  SL.setFromTriplets(t.begin(), t.end());

  Eigen::MatrixXd X(4 * n, 3);  // affine maps, identity to start
  for (int i = 0; i < n; ++i) X.middleRows(4 * i, 4) << Eigen::Matrix3d::Identity(), Eigen::RowVector3d::Zero();
  auto deformed = [&](const Eigen::MatrixXd& A) {
    Eigen::MatrixXd Y(n, 3);
    for (int i = 0; i < n; ++i) Y.row(i) = P.row(i) * A.middleRows(4 * i, 3) + A.row(4 * i + 3);
    return Y;
  };
  Eigen::SimplicialLDLT<SpMat> solver;
  const double alpha0 = opt.stiffness.empty() ? 1 : opt.stiffness.front();
  const double beta0 = opt.landmark_weight * std::sqrt(double(n) / std::max(1, nl));
  Eigen::MatrixXd Y = deformed(X), U(n, 3);
  for (double alpha : opt.stiffness) {
    const double beta = beta0 * std::pow(alpha / alpha0, opt.landmark_decay);
    for (int it = 0; it < opt.max_inner_iterations; ++it) {
      // Correspondences: closest target points of the current deformed template.
      std::vector<Eigen::Triplet<double>> td;
      Eigen::MatrixXd B = beta * beta * BL;
      for (int i = 0; i < n; ++i) {
        const ClosestPoint cp = target.closest_point(Y.row(i).transpose());
        U.row(i) = cp.point.transpose();
        if (cp.face < 0 || cp.sq_distance > max_d2) continue;
        Eigen::Vector4d d;
        d << P.row(i).transpose(), 1.0;
        for (int a = 0; a < 4; ++a) {
          for (int b = 0; b < 4; ++b) td.emplace_back(4 * i + a, 4 * i + b, d[a] * d[b]);
          B.row(4 * i + a) += d[a] * U.row(i);
        }
      }
      for (int r = 0; r < 4 * n; ++r) td.emplace_back(r, r, 1e-9);  // ridge: isolated, unmatched points
      SpMat Dd(4 * n, 4 * n);
      Dd.setFromTriplets(td.begin(), td.end());
      const SpMat A = alpha * alpha * S + Dd + beta * beta * SL;
      solver.compute(A);
      if (solver.info() != Eigen::Success) {
        out.status = Status::error(StatusCode::FactorizationFailed, "non-rigid ICP: normal matrix not positive definite");
        return out;
      }
      Eigen::MatrixXd Xn = solver.solve(B);
      ++out.solves;
      if (!Xn.allFinite()) {
        out.status = Status::error(StatusCode::NumericalError, "non-rigid ICP produced non-finite values");
        return out;
      }
      const double change = (Xn - X).cwiseAbs().maxCoeff();
      X = std::move(Xn);
      Y = deformed(X);
      if (change < opt.tolerance) break;
    }
  }
  out.X = Y;
  out.closest.resize(n, 3);
  double sum = 0;
  int valid = 0;
  for (int i = 0; i < n; ++i) {
    const ClosestPoint cp = target.closest_point(Y.row(i).transpose());
    out.closest.row(i) = cp.point.transpose();
    sum += std::sqrt(cp.sq_distance);
    if (cp.sq_distance <= max_d2) ++valid;
  }
  out.mean_residual = n > 0 ? sum / n / diag : 0;
  out.valid_fraction = n > 0 ? double(valid) / n : 0;
  out.converged = out.mean_residual <= opt.converged_residual && out.valid_fraction >= opt.converged_valid;
  return out;
}

}  // namespace mm
