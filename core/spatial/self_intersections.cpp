#include "spatial/self_intersections.h"

#include <algorithm>
#include <cmath>

#include "spatial/triangle_bvh.h"

namespace mm {

bool segment_crosses_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Möller–Trumbore with the segment parameter restricted to (0, 1). The tolerance is relative
  // so that a segment ending on the other triangle's plane (a shared-plane touch) is not a cross.
  const double eps = 1e-12;
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  const double scale = d.norm() * e1.norm() * e2.norm();
  if (!(std::abs(det) > eps * scale)) return false;  // parallel or degenerate
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = p - a;
  const double u = inv * s.dot(h);
  if (u <= eps || u >= 1 - eps) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = inv * d.dot(qv);
  if (v <= eps || u + v >= 1 - eps) return false;
  const double t = inv * e2.dot(qv);
  return t > eps && t < 1 - eps;
}

SelfIntersections self_intersections(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  SelfIntersections out;
  if (F.rows() == 0) return out;
  const TriangleBvh bvh(V, F);
  std::vector<char> involved(F.rows(), 0);
  auto corner = [&](int f, int k) -> Eigen::Vector3d { return V.row(F(f, k)).transpose(); };
  for (int f = 0; f < F.rows(); ++f) {
    Eigen::Vector3d lo = corner(f, 0), hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(corner(f, k));
      hi = hi.cwiseMax(corner(f, k));
    }
    std::vector<int> candidates;
    bvh.for_each_overlapping(lo, hi, [&](int g) {
      if (g > f) candidates.push_back(g);
    });
    std::sort(candidates.begin(), candidates.end());
    for (int g : candidates) {
      bool shared = false;
      for (int i = 0; i < 3 && !shared; ++i)
        for (int j = 0; j < 3; ++j)
          if (F(f, i) == F(g, j)) shared = true;
      if (shared) continue;
      bool hit = false;
      for (int k = 0; k < 3 && !hit; ++k) {
        hit = segment_crosses_triangle(corner(f, k), corner(f, (k + 1) % 3), corner(g, 0), corner(g, 1), corner(g, 2)) ||
              segment_crosses_triangle(corner(g, k), corner(g, (k + 1) % 3), corner(f, 0), corner(f, 1), corner(f, 2));
      }
      if (!hit) continue;
      ++out.pairs;
      involved[f] = involved[g] = 1;
      if (out.first.size() < 20) out.first.push_back({f, g});
    }
  }
  out.faces = static_cast<int>(std::count(involved.begin(), involved.end(), 1));
  return out;
}

}  // namespace mm
