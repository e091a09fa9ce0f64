#include "metrics/retarget_metrics.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Geometry>

#include "spatial/triangle_bvh.h"

namespace mm {

namespace retarget_metrics_detail {

// Signed distances of the corners of one triangle to the plane of the other.
bool coplanar_or_separated(const Eigen::Vector3d& n, double d, const Eigen::Vector3d* t, double* s) {
  for (int k = 0; k < 3; ++k) s[k] = n.dot(t[k]) + d;
  return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0);
}

// Interval of the triangle on line L (direction D) from the corners' plane distances s
// (Möller 1997, with the isolated corner on one side).
void interval(const Eigen::Vector3d* t, const double* s, const Eigen::Vector3d& D, double* lo, double* hi) {
  const double p[3] = {D.dot(t[0]), D.dot(t[1]), D.dot(t[2])};
  int lone = 0;  // the vertex alone on its side
  if ((s[0] > 0) == (s[1] > 0)) lone = 2;
  else if ((s[0] > 0) == (s[2] > 0)) lone = 1;
  else lone = 0;
  const int a = (lone + 1) % 3, b = (lone + 2) % 3;
  const double ta = p[lone] + (p[a] - p[lone]) * s[lone] / (s[lone] - s[a]);
  const double tb = p[lone] + (p[b] - p[lone]) * s[lone] / (s[lone] - s[b]);
  *lo = std::min(ta, tb);
  *hi = std::max(ta, tb);
}

bool triangles_intersect(const Eigen::Vector3d* A, const Eigen::Vector3d* B) {
  const Eigen::Vector3d n2 = (B[1] - B[0]).cross(B[2] - B[0]);
  const Eigen::Vector3d n1 = (A[1] - A[0]).cross(A[2] - A[0]);
  if (n1.squaredNorm() == 0 || n2.squaredNorm() == 0) return false;
  double sa[3], sb[3];
  if (coplanar_or_separated(n2, -n2.dot(B[0]), A, sa)) return false;
  if (coplanar_or_separated(n1, -n1.dot(A[0]), B, sb)) return false;
  // Coplanar (all zeros) or touching at a corner: not counted as an intersection.
  const double eps = 1e-12;
  if (std::abs(sa[0]) + std::abs(sa[1]) + std::abs(sa[2]) <= eps * n2.norm()) return false;
  for (int k = 0; k < 3; ++k) {
    if (sa[k] == 0) sa[k] = 1e-300;
    if (sb[k] == 0) sb[k] = 1e-300;
  }
  const Eigen::Vector3d D = n1.cross(n2);
  double a0, a1, b0, b1;
  interval(A, sa, D, &a0, &a1);
  interval(B, sb, D, &b0, &b1);
  return a1 > b0 && b1 > a0;
}

}  // namespace retarget_metrics_detail

SequenceError sequence_vertex_error(const std::vector<Eigen::MatrixXd>& A, const std::vector<Eigen::MatrixXd>& B,
                                    double scale) {
  SequenceError e;
  const size_t n = std::min(A.size(), B.size());
  e.per_frame.resize(n);
  for (size_t f = 0; f < n; ++f) {
    const Eigen::VectorXd d = (A[f] - B[f]).rowwise().norm() / scale;
    e.per_frame[f] = d.size() ? d.mean() : 0.0;
    e.max_vertex = std::max(e.max_vertex, d.size() ? d.maxCoeff() : 0.0);
  }
  if (n) {
    e.mean = e.per_frame.mean();
    e.max = e.per_frame.maxCoeff();
  }
  return e;
}

BoneLengthError bone_length_error(const std::vector<Eigen::MatrixXd>& joints,
                                  const std::vector<std::pair<int, int>>& bones, const Eigen::VectorXd& rest) {
  BoneLengthError e;
  e.per_frame = Eigen::VectorXd::Zero(joints.size());
  if (bones.empty()) return e;
  for (size_t f = 0; f < joints.size(); ++f) {
    double sum = 0;
    for (size_t b = 0; b < bones.size(); ++b) {
      const double l = (joints[f].row(bones[b].first) - joints[f].row(bones[b].second)).norm();
      const double rel = std::abs(l - rest[b]) / rest[b];
      sum += rel;
      e.max = std::max(e.max, rel);
    }
    e.per_frame[f] = sum / bones.size();
  }
  if (!joints.empty()) e.mean = e.per_frame.mean();
  return e;
}

std::vector<std::pair<int, int>> intersecting_triangle_pairs(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  std::vector<std::pair<int, int>> out;
  const TriangleBvh bvh(V, F);
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d A[3] = {V.row(F(f, 0)), V.row(F(f, 1)), V.row(F(f, 2))};
    const Eigen::Vector3d lo = A[0].cwiseMin(A[1]).cwiseMin(A[2]), hi = A[0].cwiseMax(A[1]).cwiseMax(A[2]);
    bvh.for_each_overlapping(lo, hi, [&](int g) {
      if (g <= f) return;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (F(f, i) == F(g, j)) return;  // neighbours touch by construction
      const Eigen::Vector3d B[3] = {V.row(F(g, 0)), V.row(F(g, 1)), V.row(F(g, 2))};
      if (retarget_metrics_detail::triangles_intersect(A, B)) out.push_back({f, g});
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

int self_intersection_count(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                            const std::vector<std::pair<int, int>>& ignore) {
  const auto pairs = intersecting_triangle_pairs(V, F);
  if (ignore.empty()) return static_cast<int>(pairs.size());
  int n = 0;
  for (const auto& p : pairs)
    if (!std::binary_search(ignore.begin(), ignore.end(), p)) ++n;
  return n;
}

}  // namespace mm
