// TriangleBvh: a bounding-volume hierarchy over a triangle soup for closest-point queries, ray
// and segment intersection, inside tests and box-overlap queries.
//
// The triangles need not form a manifold or even a connected surface (multi-part characters,
// polygon soups): every query works per triangle. Build is O(F log F); queries are
// O(log F) on average. Deterministic: the tree depends only on V and F (median splits on the
// longest box axis, ties broken by triangle index), and queries visit nodes in a fixed order.
//
// Conventions: V #V by 3, F #F by 3 (mesh/mesh.h); distances in the units of V.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mm {

struct ClosestPoint {
  int face = -1;                          // closest triangle (-1 when the tree is empty)
  Eigen::Vector3d point{0, 0, 0};         // closest point on that triangle
  Eigen::Vector3d barycentric{0, 0, 0};   // weights of F(face, 0..2) giving `point`
  double sq_distance = std::numeric_limits<double>::infinity();
};

class TriangleBvh {
 public:
  TriangleBvh() = default;
  TriangleBvh(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) { build(V, F); }

  // (Re)builds over V/F (copied). Degenerate triangles are kept (their closest point is still
  // well defined); ray tests skip them.
  void build(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);
  bool empty() const { return nodes_.empty(); }
  int num_faces() const { return static_cast<int>(F_.rows()); }

  // Closest point on the surface to p. `max_sq_distance` prunes: when nothing is closer,
  // the result has face = -1.
  ClosestPoint closest_point(const Eigen::Vector3d& p,
                             double max_sq_distance = std::numeric_limits<double>::infinity()) const;

  // Signed crossing count of the ray p + s·dir (s > 0) with the surface: +1 where the ray
  // leaves through a triangle (dot(normal, dir) > 0), -1 where it enters. For a closed,
  // consistently oriented surface this is the winding number of p (1 inside, 0 outside);
  // overlapping closed parts add up.
  int ray_winding(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const;

  // Distance s > 0 to the first triangle hit by the ray p + s·dir (dir need not be unit; s
  // is in units of dir), or -1 when nothing is hit within s ≤ max_s.
  double ray_first_hit(const Eigen::Vector3d& p, const Eigen::Vector3d& dir,
                       double max_s = std::numeric_limits<double>::infinity()) const;
  // Distances along the ray p + s·dir at which it crosses the surface, nearest first, up to
  // max_s and at most max_hits of them. After a hit the ray restarts `step` past it (a hit on an
  // edge shared by two triangles counts once); rays to be compared should use the same step.
  std::vector<double> ray_crossings(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, double max_s, int max_hits,
                                    double step) const;

  // Inside test robust to small holes and to inverted parts: casts 7 fixed rays and says
  // "inside" when most of them see |winding| ≥ 1. After enough queries (LazyInsideGrids below)
  // the rays are cast through a grid per direction (InsideGrids in the .cpp): the same leaves
  // and triangles are tested as by ray_winding, so the answer is the same. Thread-safe.
  bool inside(const Eigen::Vector3d& p) const;
  // The r-th of inside()'s 7 ray directions (r in 0..6).
  static Eigen::Vector3d inside_direction(int r);
  // True once inside() answers through its grids (for tests).
  bool inside_grids_ready() const { return inside_grids_ && inside_grids_->ready.load(); }
  // A hash of the tree: every node's box (bits), children and range, and the triangle order (for
  // tests: the build gives the same tree on any thread count).
  std::uint64_t fingerprint() const;

  // True when the open segment a→b crosses a triangle (endpoints lying exactly on the surface
  // do not count). `skip` may exclude triangles (e.g. those incident to the endpoints).
  bool segment_hits(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const std::function<bool(int face)>& skip = {}) const;

  // Calls visit(face) for every triangle whose bounding box overlaps [lo, hi].
  void for_each_overlapping(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                            const std::function<void(int face)>& visit) const;

  const Eigen::MatrixXd& V() const { return V_; }
  const Eigen::MatrixXi& F() const { return F_; }

 private:
  struct Node {
    Eigen::Vector3d lo, hi;  // bounding box
    int left = -1, right = -1;  // children (internal nodes)
    int first = 0, count = 0;   // range in order_ (leaves: count > 0)
  };
  struct BuildItem {  // a triangle's centroid and index, partitioned in place while building
    double c[3];
    int f;
  };
  // Appends the subtree of items[first, first + count) to `nodes` in pre-order; returns its id.
  int build_node(std::vector<Node>& nodes, int first, int count, std::vector<BuildItem>& items) const;
  // An inner node's split: items[first, first + count) partitioned at the returned middle.
  static int split_items(int first, int count, std::vector<BuildItem>& items);
  struct InsideGrids;
  // Built once, by whichever thread gets there, after inside() has cast max(256, #F / 8) queries
  // on the tree: building costs ~0.14 µs per triangle natively (2 ms at 13.8k triangles),
  // about what that many queries save, so a mesh asked a few times never pays for it.
  struct LazyInsideGrids {
    std::atomic<long> tree_queries{0};
    std::atomic<bool> ready{false};
    std::once_flag once;
    std::unique_ptr<const InsideGrids> grids;
  };
  const InsideGrids* inside_grids() const;  // null while the tree answers
  int grid_winding(const InsideGrids& g, int r, const Eigen::Vector3d& p) const;
  // Signed crossings of the ray p + s·dir (s > 0) with a leaf's triangles (its box not tested).
  int leaf_winding(const Node& n, const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const;

  Eigen::MatrixXd V_;
  Eigen::MatrixXi F_;
  std::vector<Node> nodes_;
  std::vector<int> order_;  // triangle indices, leaves reference ranges of it
  // Corner k of the triangle at position i of order_.
  Eigen::Vector3d corner(int i, int k) const { return V_.row(F_(order_[i], k)).transpose(); }
  // Shared by copies of the tree (the grids describe the same triangles); replaced by build().
  std::shared_ptr<LazyInsideGrids> inside_grids_;
};

// Closest point on triangle (a, b, c) to p, with barycentric weights (Ericson, Real-Time
// Collision Detection 5.1.5). Exposed for tests and for callers with their own candidate sets.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                          Eigen::Vector3d* barycentric);

}  // namespace mm
