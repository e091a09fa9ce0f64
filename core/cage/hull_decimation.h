// Progressive-hull decimation (Sander, Gu, Gortler, Hoppe, Snyder 2000): edge collapses in
// quadric-error order (Garland & Heckbert 1997) where the new vertex must lie on the outer side
// of the planes of all faces around the collapsed edge, so every simplified mesh encloses the
// previous one and hence the input. The second stage of the automatic cage
// (cage/enclosing_cage.h).
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

// V: #V by 3, F: #F by 3 closed outward-oriented manifold triangles.
HullDecimation hull_decimation(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                               const HullDecimationOptions& opt = {}, const Progress& progress = {});

}  // namespace mm
