#include "spatial/triangle_bvh.h"

#include "spatial/point_triangle.h"

#include <algorithm>
#include <cmath>

namespace mm {

namespace spatial_detail {

constexpr int kLeafSize = 4;

double box_sq_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}

// Slab test of the ray/segment p + s·dir, s in [0, smax], against a box.
bool ray_hits_box(const Eigen::Vector3d& p, const Eigen::Vector3d& inv_dir, double smax,
                  const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t0 = 0.0, t1 = smax;
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - p[k]) * inv_dir[k];
    double b = (hi[k] - p[k]) * inv_dir[k];
    if (a > b) std::swap(a, b);
    // NaN (0·inf when the ray lies in the slab plane) compares false and keeps the bound.
    if (a > t0) t0 = a;
    if (b < t1) t1 = b;
    if (t0 > t1) return false;
  }
  return true;
}

// Möller–Trumbore; returns the ray parameter s (> eps) or -1. `det_sign` gets the sign of
// dot(normal, dir) where normal = (b-a)x(c-a).
double ray_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, const Eigen::Vector3d& a,
                    const Eigen::Vector3d& b, const Eigen::Vector3d& c, int* det_sign) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = dir.cross(e2);
  const double det = e1.dot(h);
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) * inv;
  if (u < 0.0 || u > 1.0) return -1;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return -1;
  // Parallel or degenerate triangle. Tested after the cheap rejections (most triangles a ray's
  // boxes reach miss it), so the three square roots are paid only by hits; the result is the
  // same (with det = 0, u and v are ±inf or NaN and pass or fail the tests above, then fail here).
  const double scale = e1.norm() * e2.norm() * dir.norm();
  if (std::abs(det) <= 1e-14 * scale) return -1;
  const double t = e2.dot(q) * inv;
  // det = e1·(dir×e2) = dir·(e2×e1) = -dir·n, so the sign is flipped for dot(n, dir).
  *det_sign = det > 0 ? -1 : 1;
  return t;
}

}  // namespace spatial_detail

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                          Eigen::Vector3d* bary) {
  double w[3];
  const Eigen::Vector3d q = closest_point_on_triangle_t(
      p, a, b, c, [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) { return x.dot(y); }, w);
  *bary = {w[0], w[1], w[2]};
  return q;
}

void TriangleBvh::build(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  V_ = V;
  F_ = F;
  nodes_.clear();
  order_.resize(F.rows());
  if (F.rows() == 0) return;
  std::vector<Eigen::Vector3d> centroids(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    order_[f] = f;
    centroids[f] = (V.row(F(f, 0)) + V.row(F(f, 1)) + V.row(F(f, 2))).transpose() / 3.0;
  }
  nodes_.reserve(2 * F.rows() / spatial_detail::kLeafSize + 2);
  build_node(0, static_cast<int>(F.rows()), centroids);
}

int TriangleBvh::build_node(int first, int count, std::vector<Eigen::Vector3d>& centroids) {
  // Nodes in pre-order; a leaf's box from its triangles, an inner node's as the union of its
  // children's (the same box as from all its triangles: min and max are exact), so each triangle
  // is read once, not once per level.
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  if (count <= spatial_detail::kLeafSize) {
    Node& node = nodes_[id];
    node.lo.setConstant(std::numeric_limits<double>::infinity());
    node.hi.setConstant(-std::numeric_limits<double>::infinity());
    for (int i = first; i < first + count; ++i)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d v = V_.row(F_(order_[i], k)).transpose();
        node.lo = node.lo.cwiseMin(v);
        node.hi = node.hi.cwiseMax(v);
      }
    node.first = first;
    node.count = count;
    return id;
  }
  Eigen::Vector3d clo = centroids[order_[first]], chi = clo;
  for (int i = first; i < first + count; ++i) {
    clo = clo.cwiseMin(centroids[order_[i]]);
    chi = chi.cwiseMax(centroids[order_[i]]);
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int mid = first + count / 2;
  // Ties broken by triangle index keep the tree independent of std::nth_element internals.
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) {
                     const double ca = centroids[a][axis], cb = centroids[b][axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  const int left = build_node(first, mid - first, centroids);
  const int right = build_node(mid, first + count - mid, centroids);
  Node& node = nodes_[id];
  node.left = left;
  node.right = right;
  node.lo = nodes_[left].lo.cwiseMin(nodes_[right].lo);
  node.hi = nodes_[left].hi.cwiseMax(nodes_[right].hi);
  return id;
}

ClosestPoint TriangleBvh::closest_point(const Eigen::Vector3d& p, double max_sq_distance) const {
  ClosestPoint best;
  best.sq_distance = max_sq_distance;
  if (nodes_.empty()) return best;
  // Each entry keeps its box's squared distance, computed when it was pushed (the same value the
  // pop would compute again).
  int stack[128];
  double stack_d[128];
  int top = 0;
  stack_d[top] = spatial_detail::box_sq_distance(p, nodes_[0].lo, nodes_[0].hi);
  stack[top++] = 0;
  while (top > 0) {
    --top;
    if (stack_d[top] >= best.sq_distance) continue;
    const Node& n = nodes_[stack[top]];
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int f = order_[i];
        Eigen::Vector3d bary;
        const Eigen::Vector3d q = closest_point_on_triangle(
            p, V_.row(F_(f, 0)).transpose(), V_.row(F_(f, 1)).transpose(), V_.row(F_(f, 2)).transpose(), &bary);
        const double d = (q - p).squaredNorm();
        if (d < best.sq_distance || (d == best.sq_distance && best.face >= 0 && f < best.face)) {
          best.sq_distance = d;
          best.face = f;
          best.point = q;
          best.barycentric = bary;
        }
      }
      continue;
    }
    // Visit the nearer child first (pushed last).
    const double dl = spatial_detail::box_sq_distance(p, nodes_[n.left].lo, nodes_[n.left].hi);
    const double dr = spatial_detail::box_sq_distance(p, nodes_[n.right].lo, nodes_[n.right].hi);
    // A child no nearer than the best so far would be skipped when popped (the best only
    // shrinks): it is not pushed.
    const int near = dl <= dr ? n.left : n.right, far = dl <= dr ? n.right : n.left;
    const double dnear = std::min(dl, dr), dfar = dl <= dr ? dr : dl;
    if (dfar < best.sq_distance) stack_d[top] = dfar, stack[top++] = far;
    if (dnear < best.sq_distance) stack_d[top] = dnear, stack[top++] = near;
  }
  return best;
}

int TriangleBvh::ray_winding(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const {
  if (nodes_.empty()) return 0;
  const Eigen::Vector3d inv = dir.cwiseInverse();
  int winding = 0;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!spatial_detail::ray_hits_box(p, inv, std::numeric_limits<double>::infinity(), n.lo, n.hi)) continue;
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int f = order_[i];
        int sign = 0;
        const double t = spatial_detail::ray_triangle(p, dir, V_.row(F_(f, 0)).transpose(),
                                                      V_.row(F_(f, 1)).transpose(),
                                                      V_.row(F_(f, 2)).transpose(), &sign);
        if (t > 0) winding += sign;
      }
      continue;
    }
    stack[top++] = n.left;
    stack[top++] = n.right;
  }
  return winding;
}

double TriangleBvh::ray_first_hit(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, double max_s) const {
  if (nodes_.empty()) return -1;
  const Eigen::Vector3d inv = dir.cwiseInverse();
  double best = max_s;
  bool hit = false;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!spatial_detail::ray_hits_box(p, inv, best, n.lo, n.hi)) continue;
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int f = order_[i];
        int sign = 0;
        const double t = spatial_detail::ray_triangle(p, dir, V_.row(F_(f, 0)).transpose(),
                                                      V_.row(F_(f, 1)).transpose(),
                                                      V_.row(F_(f, 2)).transpose(), &sign);
        if (t > 1e-12 && t <= best) {
          best = t;
          hit = true;
        }
      }
      continue;
    }
    stack[top++] = n.left;
    stack[top++] = n.right;
  }
  return hit ? best : -1;
}

bool TriangleBvh::inside(const Eigen::Vector3d& p) const {
  // Irrational-ish fixed directions so that rays rarely graze edges of axis-aligned models.
  static const double dirs[7][3] = {{0.5366, 0.7071, 0.4603},  {-0.6247, 0.3312, -0.7071},
                                    {0.1118, -0.8944, 0.4331}, {-0.7771, -0.2213, 0.5893},
                                    {0.8163, -0.3397, -0.4671}, {-0.2041, 0.9613, -0.1848},
                                    {0.3015, 0.0745, -0.9505}};
  // Majority of the seven rays, stopping as soon as the majority is decided (same answer; a
  // point clearly inside or outside casts four rays instead of seven).
  int votes = 0;
  for (int r = 0; r < 7; ++r) {
    if (std::abs(ray_winding(p, Eigen::Vector3d(dirs[r][0], dirs[r][1], dirs[r][2]))) >= 1) ++votes;
    if (votes >= 4) return true;
    if (votes + (6 - r) < 4) return false;
  }
  return false;
}

bool TriangleBvh::segment_hits(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const std::function<bool(int)>& skip) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d dir = b - a;
  const double len = dir.norm();
  if (!(len > 0)) return false;
  const Eigen::Vector3d inv = dir.cwiseInverse();
  const double eps = 1e-9;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!spatial_detail::ray_hits_box(a, inv, 1.0, n.lo, n.hi)) continue;
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int f = order_[i];
        if (skip && skip(f)) continue;
        int sign = 0;
        const double t = spatial_detail::ray_triangle(a, dir, V_.row(F_(f, 0)).transpose(),
                                                      V_.row(F_(f, 1)).transpose(),
                                                      V_.row(F_(f, 2)).transpose(), &sign);
        if (t > eps && t < 1.0 - eps) return true;
      }
      continue;
    }
    stack[top++] = n.left;
    stack[top++] = n.right;
  }
  return false;
}

void TriangleBvh::for_each_overlapping(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                       const std::function<void(int)>& visit) const {
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if ((n.lo.array() > hi.array()).any() || (n.hi.array() < lo.array()).any()) continue;
    if (n.count > 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const int f = order_[i];
        Eigen::Vector3d flo = V_.row(F_(f, 0)).transpose(), fhi = flo;
        for (int k = 1; k < 3; ++k) {
          flo = flo.cwiseMin(V_.row(F_(f, k)).transpose());
          fhi = fhi.cwiseMax(V_.row(F_(f, k)).transpose());
        }
        if ((flo.array() > hi.array()).any() || (fhi.array() < lo.array()).any()) continue;
        visit(f);
      }
      continue;
    }
    stack[top++] = n.right;
    stack[top++] = n.left;
  }
}

}  // namespace mm
