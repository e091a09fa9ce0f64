// Self-intersections of a triangle mesh: pairs of triangles that cross each other (folds, a limb
// pushed through the body). Used by pose transfer to report and bound folds (issue 16).
//
// Two triangles that share no vertex intersect when an edge of one crosses the interior of the
// other (for non-coplanar triangles every intersection segment ends on such an edge crossing).
// Pairs sharing a vertex or an edge are not tested (neighbours touch by construction); coplanar
// overlaps are not counted. Candidate pairs come from the TriangleBvh's box-overlap query, so
// the cost is O(F log F) for meshes without large overlaps. Deterministic.
//
// Conventions: V #V by 3, F #F by 3 (mesh/mesh.h).
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

namespace mm {

struct SelfIntersections {
  int pairs = 0;                          // intersecting triangle pairs
  int faces = 0;                          // triangles involved in at least one pair
  std::vector<std::pair<int, int>> first; // up to 20 pairs (f < g, ascending), for messages
};

SelfIntersections self_intersections(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F);

// True when the open segment p→q crosses triangle (a, b, c) strictly inside (Möller–Trumbore;
// touching at an endpoint or along an edge within a relative 1e-12 does not count).
bool segment_crosses_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace mm
