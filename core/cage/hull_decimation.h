// Enclosure-preserving decimation: edge collapses in quadric-error order (Garland & Heckbert
// 1997) that never let a given set of points leave the surface. The second stage of the
// automatic cage (cage/enclosing_cage.h).
//
// Like the progressive hull (Sander, Gu, Gortler, Hoppe, Snyder 2000) every simplified mesh
// encloses the points, but the test is made against the points themselves, not against the
// planes of the previous surface: a collapse is refused when the generalized winding number of
// a point changes (the change is local: solid angles of the new star minus the old star) or when
// a new face comes closer than `clearance` to a point. Progressive-hull plane constraints only
// let the surface grow, which fills every concavity (legs merge, the cage tends to the convex
// hull); testing the points keeps the cage close to the offset surface.
//
// Input: a closed, consistently outward-oriented 2-manifold (e.g. cage/offset_surface.h).
// Every collapse keeps it a closed 2-manifold (link condition, no vertex of degree < 3), keeps
// face normals within `max_normal_turn` of their previous direction, and is refused when a new
// face would intersect a face it shares no vertex with (a uniform grid finds the candidates).
// The order is deterministic (ties broken by vertex index; scalar arithmetic, cage_detail.h).
// Decimation stops at the target size or when no collapse is allowed; the result can therefore
// have more vertices than asked for (thin gaps between parts block collapses that would close them).
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct HullDecimationOptions {
  int target_vertices = 300;      // stop when this many vertices remain (≥ 4)
  double max_normal_turn_deg = 75; // a collapse may turn a surviving face's normal by at most this
  double length_weight = 0.05;    // cost += weight · |edge|², favouring even edge lengths over pure
                                  // quadric error (a cage with slivers makes a poor Laplacian)
  bool check_self_intersections = true; // refuse collapses that make the surface self-intersect
};

struct HullDecimation {
  Status status;                  // InvalidMesh when the input is not a closed manifold
  Eigen::MatrixXd V;              // #C by 3 (≥ target unless the input was smaller)
  Eigen::MatrixXi F;              // #CF by 3, outward oriented
  int collapses = 0;              // collapses performed
};

// V: #V by 3, F: #F by 3 closed outward-oriented manifold triangles. P: #P by 3 points to keep
// inside (may be empty); clearance: distance (mesh units) new faces keep from every point.
HullDecimation hull_decimation(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                               const Eigen::MatrixXd& P, double clearance,
                               const HullDecimationOptions& opt = {}, const Progress& progress = {});

}  // namespace mm
