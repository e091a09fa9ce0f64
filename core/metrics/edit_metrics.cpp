#include "metrics/edit_metrics.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "linalg/polar.h"
#include "linalg/rigid_fit.h"
#include "mesh/topology.h"
#include "operators/operators.h"

namespace mm {

namespace edit_metrics_detail {

// Umeyama fit of a similarity between two point sets (rows; linalg/rigid_fit.h). Returns the
// rotation and writes the residual sum of squares and Σ|q − q̄|².
Eigen::Matrix3d edit_metrics_umeyama(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q, double* residual2,
                                     double* q_spread2) {
  RigidFitOptions o;
  o.scale = true;
  const RigidFit fit = fit_rigid(P, Q, o);
  if (residual2) *residual2 = fit.residual2;
  if (q_spread2) *q_spread2 = fit.target_spread2;
  return fit.R;
}

Eigen::MatrixXd edit_metrics_ring_points(const Eigen::MatrixXd& X, int i, const std::vector<int>& ring) {
  Eigen::MatrixXd P(ring.size() + 1, 3);
  P.row(0) = X.row(i);
  for (size_t k = 0; k < ring.size(); ++k) P.row(static_cast<Eigen::Index>(k) + 1) = X.row(ring[k]);
  return P;
}

}  // namespace edit_metrics_detail

using namespace edit_metrics_detail;

Eigen::VectorXd local_rigidity_error(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F) {
  const int n = static_cast<int>(V0.rows());
  const auto adj = vertex_adjacency(F, n);
  Eigen::VectorXd err = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    if (adj[i].size() < 2) continue;
    double res2 = 0, q2 = 0;
    edit_metrics_umeyama(edit_metrics_ring_points(V0, i, adj[i]), edit_metrics_ring_points(V1, i, adj[i]), &res2, &q2);
    if (q2 > 0) err[i] = std::sqrt(res2 / q2);
  }
  return err;
}

Eigen::MatrixXd fitted_gradients(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F) {
  const int n = static_cast<int>(V0.rows());
  const auto adj = vertex_adjacency(F, n);
  const Eigen::MatrixXd N0 = vertex_normals(V0, F), N1 = vertex_normals(V1, F);
  Eigen::MatrixXd G(n, 9);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> M = Eigen::Matrix3d::Identity();
    if (!adj[i].empty()) {
      const int m = static_cast<int>(adj[i].size());
      Eigen::MatrixXd A(3, m + 2), B(3, m + 2);
      Eigen::Vector3d c0 = Eigen::Vector3d::Zero(), c1 = Eigen::Vector3d::Zero();
      for (int j : adj[i]) {
        c0 += V0.row(j).transpose();
        c1 += V1.row(j).transpose();
      }
      c0 /= m;
      c1 /= m;
      double h0 = 0, h1 = 0;
      A.col(0) = V0.row(i).transpose() - c0;
      B.col(0) = V1.row(i).transpose() - c1;
      for (int k = 0; k < m; ++k) {
        const int j = adj[i][k];
        A.col(k + 1) = V0.row(j).transpose() - c0;
        B.col(k + 1) = V1.row(j).transpose() - c1;
        h0 += (V0.row(j) - V0.row(i)).norm();
        h1 += (V1.row(j) - V1.row(i)).norm();
      }
      A.col(m + 1) = (h0 / m) * N0.row(i).transpose();
      B.col(m + 1) = (h1 / m) * N1.row(i).transpose();
      const Eigen::Matrix3d AA = A * A.transpose();
      if (std::abs(AA.determinant()) > 0) M = B * A.transpose() * AA.inverse();
    }
    G.row(i) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(M.data());
  }
  return G;
}

double gradient_shear(const Eigen::Matrix3d& M) {
  const Polar3 p = polar_decomposition(M);
  const double s = std::sqrt(p.singular_values.squaredNorm() / 3.0);
  if (!(s > 0) || !std::isfinite(s)) return 0.0;
  return (p.S - s * Eigen::Matrix3d::Identity()).norm() / (std::sqrt(3.0) * s);
}

Eigen::VectorXd gradient_shear(const Eigen::MatrixXd& G) {
  Eigen::VectorXd out(G.rows());
  for (int i = 0; i < G.rows(); ++i) {
    const Eigen::Matrix<double, 1, 9> row = G.row(i);  // G is column-major: copy the strided row
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> M = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(row.data());
    out[i] = gradient_shear(Eigen::Matrix3d(M));
  }
  return out;
}

EdgeDistortion edge_length_distortion(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F) {
  EdgeDistortion d;
  long count = 0;
  for (const auto& e : edge_uses(F)) {
    const double l0 = (V0.row(e.i) - V0.row(e.j)).norm(), l1 = (V1.row(e.i) - V1.row(e.j)).norm();
    if (!(l0 > 0)) continue;
    const double r = std::abs(l1 - l0) / l0;
    d.mean += r;
    d.max = std::max(d.max, r);
    ++count;
  }
  if (count > 0) d.mean /= static_cast<double>(count);
  return d;
}

Eigen::VectorXd laplacian_normal_angle(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F) {
  const Eigen::MatrixXd L = cotan_stiffness(V0, F) * V1;  // −(Voronoi area/2)·D(ṽ); only its line matters
  const Eigen::MatrixXd& V = V1;
  const Eigen::MatrixXd N = vertex_normals(V, F);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(V.rows());
  for (int i = 0; i < V.rows(); ++i) {
    const double l = L.row(i).norm();
    if (!(l > 0) || N.row(i).squaredNorm() == 0) continue;
    const double c = std::min(1.0, std::abs(L.row(i).dot(N.row(i))) / l);
    a[i] = std::acos(c) * 180.0 / M_PI;
  }
  return a;
}

DetailPreservation detail_preservation(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F,
                                       const std::vector<int>& vertices) {
  const Eigen::VectorXd w = (cotan_stiffness(V0, F) * V0).rowwise().norm();
  const Eigen::VectorXd a0 = laplacian_normal_angle(V0, V0, F), a1 = laplacian_normal_angle(V0, V1, F);
  DetailPreservation out;
  double sw = 0;
  auto add = [&](int i) {
    sw += w[i];
    out.mean_angle_deg += w[i] * a1[i];
    out.rest_mean_angle_deg += w[i] * a0[i];
  };
  if (vertices.empty())
    for (int i = 0; i < V0.rows(); ++i) add(i);
  else
    for (int i : vertices) add(i);
  if (sw > 0) {
    out.mean_angle_deg /= sw;
    out.rest_mean_angle_deg /= sw;
  }
  return out;
}

std::vector<int> inverted_faces(const Eigen::MatrixXd& V0, const Eigen::MatrixXd& V1, const Eigen::MatrixXi& F) {
  const int n = static_cast<int>(V0.rows());
  const auto adj = vertex_adjacency(F, n);
  const Eigen::MatrixXd N0 = face_normals(V0, F), N1 = face_normals(V1, F);
  std::vector<int> out;
  std::vector<int> pts;
  for (int f = 0; f < F.rows(); ++f) {
    pts.clear();
    for (int c = 0; c < 3; ++c) {
      pts.push_back(F(f, c));
      pts.insert(pts.end(), adj[F(f, c)].begin(), adj[F(f, c)].end());
    }
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    Eigen::MatrixXd P(pts.size(), 3), Q(pts.size(), 3);
    for (size_t k = 0; k < pts.size(); ++k) {
      P.row(static_cast<Eigen::Index>(k)) = V0.row(pts[k]);
      Q.row(static_cast<Eigen::Index>(k)) = V1.row(pts[k]);
    }
    if (N0.row(f).squaredNorm() == 0) continue;  // degenerate at rest: orientation undefined
    const Eigen::Matrix3d R = edit_metrics_umeyama(P, Q, nullptr, nullptr);
    const Eigen::Vector3d n0 = R * N0.row(f).transpose();
    if (N1.row(f).squaredNorm() == 0 || N1.row(f).dot(n0) <= 0) out.push_back(f);
  }
  return out;
}

double mean_over(const Eigen::VectorXd& v, const std::vector<int>& subset) {
  if (subset.empty()) return v.size() ? v.mean() : 0.0;
  double s = 0;
  for (int i : subset) s += v[i];
  return s / static_cast<double>(subset.size());
}

}  // namespace mm
