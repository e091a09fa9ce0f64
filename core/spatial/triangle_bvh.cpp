#include "spatial/triangle_bvh.h"

#include "common/threads.h"
#include "spatial/point_triangle.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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

// Below this many triangles the build takes < ~2 ms on one thread and is not split.
constexpr int kParallelBuild = 16384;

void TriangleBvh::build(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  V_ = V;
  F_ = F;
  nodes_.clear();
  inside_grids_ = std::make_shared<LazyInsideGrids>();
  order_.resize(F.rows());
  if (F.rows() == 0) return;
  // Centroids travel with their triangle's index, so partitioning reads them in sequence (this
  // used to sort indices into a separate centroid array: the same comparisons on the same
  // sequence, so the same tree and the same order_, without a cache miss per comparison).
  std::vector<BuildItem> items(F.rows());
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d c = (V.row(F(f, 0)) + V.row(F(f, 1)) + V.row(F(f, 2))).transpose() / 3.0;
    items[f] = {{c[0], c[1], c[2]}, f};
  }
  const int n = static_cast<int>(F.rows());
  nodes_.reserve(2 * n / spatial_detail::kLeafSize + 2);
  if (n < kParallelBuild || max_threads() < 2) {
    build_node(nodes_, 0, n, items);
  } else {
    // Two threads: the root's halves are built apart, the right one into a node array of its own
    // that is appended after the left one with its child ids shifted. Pre-order puts the whole left
    // subtree before the right one, so the nodes, their ids and order_ are those of one thread.
    nodes_.emplace_back();
    const int mid = split_items(0, n, items);
    std::vector<Node> right_nodes;
    right_nodes.reserve(2 * (n - mid) / spatial_detail::kLeafSize + 2);
    Task right([this, &right_nodes, mid, n, &items] { build_node(right_nodes, mid, n - mid, items); });
    const int left = build_node(nodes_, 0, mid, items);
    right.wait();
    const int shift = static_cast<int>(nodes_.size());
    for (Node& node : right_nodes)
      if (node.count == 0) node.left += shift, node.right += shift;
    nodes_.insert(nodes_.end(), right_nodes.begin(), right_nodes.end());
    Node& root = nodes_[0];
    root.left = left;
    root.right = shift;
    root.lo = nodes_[left].lo.cwiseMin(nodes_[shift].lo);
    root.hi = nodes_[left].hi.cwiseMax(nodes_[shift].hi);
  }
  for (int i = 0; i < n; ++i) order_[i] = items[i].f;
}

std::uint64_t TriangleBvh::fingerprint() const {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the words below
  auto mix = [&h](std::uint64_t w) {
    for (int b = 0; b < 8; ++b) h = (h ^ ((w >> (8 * b)) & 0xff)) * 1099511628211ull;
  };
  auto bits = [](double x) {
    std::uint64_t w;
    std::memcpy(&w, &x, sizeof w);
    return w;
  };
  for (const Node& n : nodes_) {
    for (int k = 0; k < 3; ++k) mix(bits(n.lo[k])), mix(bits(n.hi[k]));
    mix(std::uint64_t(std::uint32_t(n.left)) << 32 | std::uint32_t(n.right));
    mix(std::uint64_t(std::uint32_t(n.first)) << 32 | std::uint32_t(n.count));
  }
  for (int f : order_) mix(std::uint32_t(f));
  return h;
}

int TriangleBvh::split_items(int first, int count, std::vector<BuildItem>& items) {
  double clo[3] = {items[first].c[0], items[first].c[1], items[first].c[2]}, chi[3] = {clo[0], clo[1], clo[2]};
  for (int i = first; i < first + count; ++i)
    for (int k = 0; k < 3; ++k) clo[k] = std::min(clo[k], items[i].c[k]), chi[k] = std::max(chi[k], items[i].c[k]);
  int axis = 0;
  Eigen::Vector3d(chi[0] - clo[0], chi[1] - clo[1], chi[2] - clo[2]).maxCoeff(&axis);
  const int mid = first + count / 2;
  // Ties broken by triangle index keep the tree independent of std::nth_element internals.
  std::nth_element(items.begin() + first, items.begin() + mid, items.begin() + first + count,
                   [axis](const BuildItem& a, const BuildItem& b) {
                     return a.c[axis] < b.c[axis] || (a.c[axis] == b.c[axis] && a.f < b.f);
                   });
  return mid;
}

int TriangleBvh::build_node(std::vector<Node>& nodes, int first, int count, std::vector<BuildItem>& items) const {
  // Nodes in pre-order; a leaf's box from its triangles, an inner node's as the union of its
  // children's (the same box as from all its triangles: min and max are exact), so each triangle
  // is read once, not once per level.
  const int id = static_cast<int>(nodes.size());
  nodes.emplace_back();
  if (count <= spatial_detail::kLeafSize) {
    Node& node = nodes[id];
    node.lo.setConstant(std::numeric_limits<double>::infinity());
    node.hi.setConstant(-std::numeric_limits<double>::infinity());
    for (int i = first; i < first + count; ++i)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d v = V_.row(F_(items[i].f, k)).transpose();
        node.lo = node.lo.cwiseMin(v);
        node.hi = node.hi.cwiseMax(v);
      }
    node.first = first;
    node.count = count;
    return id;
  }
  const int mid = split_items(first, count, items);
  const int left = build_node(nodes, first, mid - first, items);
  const int right = build_node(nodes, mid, first + count - mid, items);
  Node& node = nodes[id];
  node.left = left;
  node.right = right;
  node.lo = nodes[left].lo.cwiseMin(nodes[right].lo);
  node.hi = nodes[left].hi.cwiseMax(nodes[right].hi);
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
        const Eigen::Vector3d q = closest_point_on_triangle(p, corner(i, 0), corner(i, 1), corner(i, 2), &bary);
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

int TriangleBvh::leaf_winding(const Node& n, const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const {
  int winding = 0;
  for (int i = n.first; i < n.first + n.count; ++i) {
    int sign = 0;
    const double t = spatial_detail::ray_triangle(p, dir, corner(i, 0), corner(i, 1), corner(i, 2), &sign);
    if (t > 0) winding += sign;
  }
  return winding;
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
      winding += leaf_winding(n, p, dir);
      continue;
    }
    stack[top++] = n.left;
    stack[top++] = n.right;
  }
  return winding;
}

std::vector<double> TriangleBvh::ray_crossings(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, double max_s,
                                               int max_hits, double step) const {
  std::vector<double> hits;
  double s0 = 0;
  while (static_cast<int>(hits.size()) < max_hits) {
    const double s = ray_first_hit(p + s0 * dir, dir, max_s - s0);
    if (s < 0) break;
    hits.push_back(s0 + s);
    s0 += s + step;
    if (s0 >= max_s) break;
  }
  return hits;
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
        int sign = 0;
        const double t = spatial_detail::ray_triangle(p, dir, corner(i, 0), corner(i, 1), corner(i, 2), &sign);
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

namespace {

// The inside test's rays: irrational-ish fixed directions so that they rarely graze edges of
// axis-aligned models.
constexpr double kInsideDirs[7][3] = {{0.5366, 0.7071, 0.4603},  {-0.6247, 0.3312, -0.7071},
                                      {0.1118, -0.8944, 0.4331}, {-0.7771, -0.2213, 0.5893},
                                      {0.8163, -0.3397, -0.4671}, {-0.2041, 0.9613, -0.1848},
                                      {0.3015, 0.0745, -0.9505}};

}  // namespace

// Per inside ray direction d: the leaves' boxes projected along d onto a plane (orthonormal u, w
// ⟂ d), each binned into the cells of a uniform 2D grid its projected bounding rectangle
// overlaps. A ray p + s·d meets a box only if (p·u, p·w) lies in the box's projection, so the
// leaves binned in p's cell are a superset of the leaves whose box the ray meets. Rectangles are
// widened by 1e-9 of the scene's size, well above the rounding of the projections and of the
// slab test. Each candidate leaf then gets the very slab test the tree's traversal gives it (a
// leaf passing it has every ancestor passing: the ancestors' bounds are exact mins and maxes of
// their children's, and the slab test is monotone in them) and the same ray–triangle tests, so
// the winding is the traversal's — at a cost of one cell's leaves instead of every box the ray
// crosses (the retargeter's MFS maps cast ~25k inside tests each: a quarter of its precompute).
struct TriangleBvh::InsideGrids {
  struct Grid {
    Eigen::Vector3d dir, u, w;
    double u0 = 0, w0 = 0, inv_cell = 0;
    int nu = 0, nw = 0;
    std::vector<int> start;   // nu·nw + 1 offsets into leaves
    std::vector<int> leaves;  // node ids
  };
  Grid grid[7];
};

const TriangleBvh::InsideGrids* TriangleBvh::inside_grids() const {
  LazyInsideGrids& lazy = *inside_grids_;
  if (lazy.ready.load(std::memory_order_acquire)) return lazy.grids.get();
  if (lazy.tree_queries.fetch_add(1, std::memory_order_relaxed) < std::max<long>(256, F_.rows() / 8)) return nullptr;
  std::call_once(lazy.once, [&] {
    auto g = std::make_unique<InsideGrids>();
    std::vector<int> leaves;
    for (size_t i = 0; i < nodes_.size(); ++i)
      if (nodes_[i].count > 0) leaves.push_back(static_cast<int>(i));
    const Node& root = nodes_[0];
    const double scale = (root.hi - root.lo).norm() + root.lo.cwiseAbs().cwiseMax(root.hi.cwiseAbs()).maxCoeff();
    const double margin = 1e-9 * scale + 1e-300;
    const size_t nl = leaves.size();
    std::vector<double> rect(4 * nl);  // umin, umax, wmin, wmax per leaf
    for (int r = 0; r < 7; ++r) {
      InsideGrids::Grid& G = g->grid[r];
      G.dir = inside_direction(r);
      const Eigen::Vector3d d = G.dir.normalized();
      int a = 0;
      d.cwiseAbs().minCoeff(&a);
      G.u = d.cross(Eigen::Vector3d::Unit(a)).normalized();
      G.w = d.cross(G.u).normalized();
      double u_lo = std::numeric_limits<double>::infinity(), u_hi = -u_lo, w_lo = u_lo, w_hi = -u_lo;
      for (size_t l = 0; l < nl; ++l) {
        const Node& n = nodes_[leaves[l]];
        double* q = &rect[4 * l];
        q[0] = q[2] = std::numeric_limits<double>::infinity();
        q[1] = q[3] = -std::numeric_limits<double>::infinity();
        for (int c = 0; c < 8; ++c) {
          const Eigen::Vector3d x((c & 1) ? n.hi[0] : n.lo[0], (c & 2) ? n.hi[1] : n.lo[1], (c & 4) ? n.hi[2] : n.lo[2]);
          const double pu = x.dot(G.u), pw = x.dot(G.w);
          q[0] = std::min(q[0], pu), q[1] = std::max(q[1], pu), q[2] = std::min(q[2], pw), q[3] = std::max(q[3], pw);
        }
        q[0] -= margin, q[1] += margin, q[2] -= margin, q[3] += margin;
        u_lo = std::min(u_lo, q[0]), u_hi = std::max(u_hi, q[1]), w_lo = std::min(w_lo, q[2]), w_hi = std::max(w_hi, q[3]);
      }
      // About one cell per leaf, square cells, at most 2048 along a side.
      const double eu = u_hi - u_lo, ew = w_hi - w_lo;
      const double cell = std::max(std::sqrt(eu * ew / static_cast<double>(nl)), std::max(eu, ew) / 2048);
      G.u0 = u_lo, G.w0 = w_lo, G.inv_cell = 1.0 / cell;
      G.nu = std::clamp(static_cast<int>(eu * G.inv_cell) + 1, 1, 2049);
      G.nw = std::clamp(static_cast<int>(ew * G.inv_cell) + 1, 1, 2049);
      const auto cell_of = [&](double x, double x0, int n) {
        return std::clamp(static_cast<int>(std::floor((x - x0) * G.inv_cell)), 0, n - 1);
      };
      // Cells as CSR: count the leaves per cell, prefix sums, then fill through a cursor per cell.
      G.start.assign(static_cast<size_t>(G.nu) * G.nw + 1, 0);
      const auto for_each_cell = [&](size_t l, const auto& visit) {
        const double* q = &rect[4 * l];
        const int iu0 = cell_of(q[0], G.u0, G.nu), iu1 = cell_of(q[1], G.u0, G.nu);
        const int iw0 = cell_of(q[2], G.w0, G.nw), iw1 = cell_of(q[3], G.w0, G.nw);
        for (int iw = iw0; iw <= iw1; ++iw)
          for (int iu = iu0; iu <= iu1; ++iu) visit(static_cast<size_t>(iw) * G.nu + iu);
      };
      for (size_t l = 0; l < nl; ++l) for_each_cell(l, [&](size_t c) { ++G.start[c + 1]; });
      for (size_t c = 1; c < G.start.size(); ++c) G.start[c] += G.start[c - 1];
      G.leaves.resize(G.start.back());
      std::vector<int> cursor(G.start.begin(), G.start.end() - 1);
      for (size_t l = 0; l < nl; ++l) for_each_cell(l, [&](size_t c) { G.leaves[cursor[c]++] = leaves[l]; });
    }
    lazy.grids = std::move(g);
    lazy.ready.store(true, std::memory_order_release);
  });
  return lazy.grids.get();
}

int TriangleBvh::grid_winding(const InsideGrids& g, int r, const Eigen::Vector3d& p) const {
  const InsideGrids::Grid& G = g.grid[r];
  const double fu = (p.dot(G.u) - G.u0) * G.inv_cell, fw = (p.dot(G.w) - G.w0) * G.inv_cell;
  // Outside the grid (or not finite): no leaf's projection holds p, the ray meets no box.
  if (!(fu >= 0 && fu < G.nu && fw >= 0 && fw < G.nw)) return 0;
  const size_t c = static_cast<size_t>(static_cast<int>(fw)) * G.nu + static_cast<int>(fu);
  const Eigen::Vector3d inv = G.dir.cwiseInverse();
  int winding = 0;
  for (int k = G.start[c]; k < G.start[c + 1]; ++k) {
    const Node& n = nodes_[G.leaves[k]];
    if (spatial_detail::ray_hits_box(p, inv, std::numeric_limits<double>::infinity(), n.lo, n.hi))
      winding += leaf_winding(n, p, G.dir);
  }
  return winding;
}

Eigen::Vector3d TriangleBvh::inside_direction(int r) {
  return Eigen::Vector3d(kInsideDirs[r][0], kInsideDirs[r][1], kInsideDirs[r][2]);
}

bool TriangleBvh::inside(const Eigen::Vector3d& p) const {
  if (nodes_.empty()) return false;
  const InsideGrids* g = inside_grids();
  // Majority of the seven rays, stopping as soon as the majority is decided (same answer; a
  // point clearly inside or outside casts four rays instead of seven).
  int votes = 0;
  for (int r = 0; r < 7; ++r) {
    const int w = g ? grid_winding(*g, r, p) : ray_winding(p, inside_direction(r));
    if (std::abs(w) >= 1) ++votes;
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
        const double t = spatial_detail::ray_triangle(a, dir, corner(i, 0), corner(i, 1), corner(i, 2), &sign);
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
        Eigen::Vector3d flo = corner(i, 0), fhi = flo;
        for (int k = 1; k < 3; ++k) {
          flo = flo.cwiseMin(corner(i, k));
          fhi = fhi.cwiseMax(corner(i, k));
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
