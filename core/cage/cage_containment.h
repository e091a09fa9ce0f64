// Which points lie strictly inside a closed triangle cage: winding number by ray parity plus a
// clearance check. Used to validate automatic and user-given cages before mean-value
// coordinates are computed (cage/mean_value_coordinates.h needs every point inside).
//
// The winding number of a point is the signed number of cage faces crossed by the ray from the
// point along +x (+1 for a face whose outward normal has positive x). Ties (the ray through an
// edge or vertex of the projection) are broken by a fixed symbolic perturbation of the ray,
// so a closed cage is always counted consistently: +1 inside an outward-oriented cage, -1
// inside an inward-oriented one, 0 outside.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct CageContainment {
  Status status;                 // InvalidArgument for an empty cage or bad indices
  Eigen::VectorXi winding;       // #P winding numbers (see above)
  Eigen::VectorXd distance;      // #P distance to the cage surface, capped at `clearance`
                                 // (values ≥ clearance mean "at least clearance")
  std::vector<int> not_inside;   // points with winding ≠ +1 or distance < clearance, ascending
};

// P: #P by 3 points; C: #C by 3 cage vertices; CF: #CF by 3 cage triangles (closed surface);
// clearance: distance (mesh units) a point must keep from the cage to count as inside.
CageContainment cage_containment(const Eigen::MatrixXd& P, const Eigen::MatrixXd& C,
                                 const Eigen::MatrixXi& CF, double clearance);

}  // namespace mm
