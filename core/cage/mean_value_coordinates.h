// Mean-value coordinates of points with respect to a closed triangle cage (Ju, Schaefer, Warren,
// "Mean value coordinates for closed triangular meshes", SIGGRAPH 2005).
//
// Ψ (#P by #C, dense) has rows that sum to 1 (partition of unity) and reproduce the points,
// P = Ψ C (linear precision), for every point not on the cage; a deformed cage C̃ gives the
// deformed points Ψ C̃ (paper 000 Sec. 4.2: V = ΨC, Ṽ = ΨC̃).
//
// Robustness: the per-face weights use the exact form
//   w_i = sin θ_i (θ_i − c_{i+1} θ_{i−1} − c_{i−1} θ_{i+1}) / (d_i det[u₁ u₂ u₃]),
//   c_i = (cos θ_i − cos θ_{i+1} cos θ_{i−1}) / (sin θ_{i+1} sin θ_{i−1}),
// which equals JSW's Fig. 4 pseudocode (their s_i = sign(det)·√(1 − c_i²) is det/(sin θ_{i+1}
// sin θ_{i−1}) exactly) without the √(1 − c²) cancellation near a face's plane. sin θ and cos θ
// come from the chord |u_a − u_b| algebraically; θ = 2 asin(chord/2) is accurate for all angles.
// A point within 1e-12 (relative) of a cage vertex gets that vertex's unit row; a point on a
// face (spherical excess ~2π, det ≈ 0) gets the face's barycentric coordinates; a face whose
// plane contains the point (|det| < 1e-10) outside the face contributes nothing (its true
// contribution is of the same order). Tested to reproduce points 1e-9 from a face.
//
// Points outside the cage get coordinates too (the identities hold, but weights are no longer
// meaningful); callers check containment first (cage/cage_containment.h).
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct MeanValueCoordinates {
  Status status;     // InvalidArgument for a bad cage, NumericalError if a row is non-finite
                     // (a point whose weights cancel, e.g. far outside), Cancelled
  Eigen::MatrixXd Psi; // #P by #C
};

// P: #P by 3 points, C: #C by 3 cage vertices, CF: #CF by 3 closed, outward-oriented cage faces.
MeanValueCoordinates mean_value_coordinates(const Eigen::MatrixXd& P, const Eigen::MatrixXd& C,
                                            const Eigen::MatrixXi& CF, const Progress& progress = {});

}  // namespace mm
