#include "retarget/context_graph.h"

#include <algorithm>
#include <cassert>
#include <limits>

#include "mesh/mesh.h"

namespace mm {

Eigen::VectorXi nearest_centers(const Eigen::MatrixXd& X, const Eigen::MatrixXd& centers) {
  Eigen::VectorXi label(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    int arg = 0;
    for (Eigen::Index c = 0; c < centers.rows(); ++c) {
      const double d = (X.row(i) - centers.row(c)).squaredNorm();
      if (d < best) best = d, arg = static_cast<int>(c);
    }
    label[i] = arg;
  }
  return label;
}

BodyParts body_parts(const Eigen::MatrixXd& P, const Eigen::MatrixXd& joints, int iterations) {
  assert(joints.rows() > 0 && "body parts need at least one joint");
  BodyParts out;
  out.centers = joints;
  out.label = nearest_centers(P, out.centers);
  // Lloyd iterations in a fixed order (sums in point order): deterministic on every platform.
  for (int it = 0; it < iterations; ++it) {
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(joints.rows(), 3);
    Eigen::VectorXi count = Eigen::VectorXi::Zero(joints.rows());
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
      sum.row(out.label[i]) += P.row(i);
      ++count[out.label[i]];
    }
    for (Eigen::Index c = 0; c < joints.rows(); ++c)
      if (count[c] > 0) out.centers.row(c) = sum.row(c) / count[c];
    Eigen::VectorXi next = nearest_centers(P, out.centers);
    const bool same = next == out.label;
    out.label = std::move(next);
    if (same) break;
  }
  return out;
}

Eigen::MatrixXd SurfaceNodes::positions(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) const {
  Eigen::MatrixXd X(size(), 3);
  for (int i = 0; i < size(); ++i) {
    X.row(i).setZero();
    for (int c = 0; c < 3; ++c) X.row(i) += barycentric(i, c) * V.row(F(face[i], c));
  }
  return X;
}

SurfaceNodes project_to_surface(const Eigen::MatrixXd& Q, const TriangleBvh& bvh, double merge_distance) {
  std::vector<ClosestPoint> kept;
  std::vector<int> src;
  const double m2 = merge_distance * merge_distance;
  for (Eigen::Index q = 0; q < Q.rows(); ++q) {
    const ClosestPoint cp = bvh.closest_point(Q.row(q).transpose());
    if (cp.face < 0) continue;
    bool dup = false;
    for (const ClosestPoint& k : kept)
      if ((k.point - cp.point).squaredNorm() < m2) {
        dup = true;
        break;
      }
    if (dup) continue;
    kept.push_back(cp);
    src.push_back(static_cast<int>(q));
  }
  SurfaceNodes n;
  const int N = static_cast<int>(kept.size());
  n.face.resize(N);
  n.barycentric.resize(N, 3);
  n.P.resize(N, 3);
  n.source.resize(N);
  for (int i = 0; i < N; ++i) {
    n.face[i] = kept[i].face;
    n.barycentric.row(i) = kept[i].barycentric.transpose();
    n.P.row(i) = kept[i].point.transpose();
    n.source[i] = src[i];
  }
  return n;
}

std::vector<std::pair<int, int>> pruned_context_edges(const Eigen::MatrixXd& P, const Eigen::VectorXi& part,
                                                      const TriangleBvh& bvh, double height,
                                                      const ContextGraphOptions& opt, PruneCounts* counts) {
  assert(part.size() == P.rows());
  PruneCounts c;
  std::vector<std::pair<int, int>> edges;
  const int n = static_cast<int>(P.rows());
  const double max_len = opt.max_edge_length * height;
  const double margin = opt.segment_margin * bounding_box_diagonal(bvh.V());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      ++c.complete;
      if (part[i] == part[j]) {  // rule (1): same body part
        ++c.same_part;
        continue;
      }
      const Eigen::Vector3d a = P.row(i).transpose(), b = P.row(j).transpose();
      const double len = (b - a).norm();
      if (len > max_len) {  // rule (2): long edge
        ++c.too_long;
        continue;
      }
      // Rule (3): the segment enters the interior. The endpoints lie on the surface, so the
      // segment is shortened a little; a chord that stays inside crosses nothing, hence the
      // midpoint test.
      bool interior = len <= 2 * margin;  // coincident nodes of two parts: no usable direction
      if (!interior) {
        const Eigen::Vector3d d = (b - a) / len;
        interior = bvh.segment_hits(a + margin * d, b - margin * d) || bvh.inside(0.5 * (a + b));
      }
      if (interior) {
        ++c.interior;
        continue;
      }
      edges.push_back({i, j});
    }
  c.kept = static_cast<int>(edges.size());
  if (counts) *counts = c;
  return edges;
}

Eigen::SparseMatrix<double> uniform_graph_laplacian(int n, const std::vector<std::pair<int, int>>& edges) {
  std::vector<int> degree(n, 0);
  for (const auto& [i, j] : edges) ++degree[i], ++degree[j];
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i)
    if (degree[i] > 0) t.emplace_back(i, i, 1.0);
  for (const auto& [i, j] : edges) {
    t.emplace_back(i, j, -1.0 / degree[i]);
    t.emplace_back(j, i, -1.0 / degree[j]);
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(t.begin(), t.end());
  return L;
}

std::vector<std::pair<int, int>> edge_union(const std::vector<std::pair<int, int>>& a,
                                            const std::vector<std::pair<int, int>>& b) {
  std::vector<std::pair<int, int>> u(a);
  u.insert(u.end(), b.begin(), b.end());
  std::sort(u.begin(), u.end());
  u.erase(std::unique(u.begin(), u.end()), u.end());
  return u;
}

}  // namespace mm
