// Automatic coarse cage around a triangle mesh ("offset and simplify"), and validation of a cage
// a user supplies. The cage is the control mesh of the mean-value-coordinate subspace used by
// pose transfer (paper 000 Sec. 4.2); the retarget module reuses it for singularity points.
//
// enclosing_cage: offset surface on a voxel grid (cage/offset_surface.h), then progressive-hull
// decimation to about `target_vertices` (cage/hull_decimation.h). Guarantees, checked before
// returning (cage/cage_containment.h): the cage is a closed, outward-oriented 2-manifold
// (counter-clockwise seen from outside, mesh/mesh.h), and every input vertex lies strictly inside
// it, at least `min_clearance` × bbox diagonal from its surface. Vertices that end up too close
// (the voxel approximation) are fixed by pushing the nearest cage faces outward; if that fails
// the status is NumericalError and the message says how many vertices are outside.
//
// Works on non-manifold, inconsistently oriented or slightly open meshes (voxelisation only
// needs the triangles). Deterministic, and bit-identical natively and in wasm.
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct EnclosingCageOptions {
  int target_vertices = 300;    // cage size; ~150–500 suits pose transfer (paper 000 Table 1: 166–520)
  int resolution = 80;          // offset grid cells along the longest bbox side; higher keeps
                                // nearby parts (legs) apart at the cost of time (96: 1.4× the
                                // time, no better transfers on the cat/lion pairs; 64: cat-07 worse)
  double offset_voxels = 3.0;   // offset distance in voxels before simplification
  double min_clearance = 1e-3;  // every input vertex at least this × bbox diagonal inside the cage
  double max_normal_turn_deg = 75; // decimation: largest normal change of a face per collapse
  double length_weight = 0.05;  // decimation: preference for even edge lengths (hull_decimation.h)
  int repair_rounds = 8;        // rounds of pushing cage faces outward past too-close vertices
};

struct EnclosingCage {
  Status status;               // see header comment
  Eigen::MatrixXd V;           // #C by 3 cage vertices
  Eigen::MatrixXi F;           // #CF by 3 outward-oriented cage triangles
  int offset_vertices = 0;     // size of the offset surface before decimation
  int collapses = 0;           // edge collapses performed
  int repaired_vertices = 0;   // cage vertices moved by the clearance repair
  double min_distance = 0;     // smallest distance from an input vertex to the cage (mesh units,
                               // capped at 10 × the required clearance)
};

// V: #V by 3, F: #F by 3 (any topology).
EnclosingCage enclosing_cage(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const EnclosingCageOptions& opt = {}, const Progress& progress = {});

// Checks a user-given cage (C, CF) for mesh vertices V: closed manifold, every vertex strictly
// inside (clearance × bbox diagonal of V). An inward-oriented cage is flipped (CF is rewritten).
// Errors: InvalidMesh "cage has 3 boundary edges ..." or "cage encloses 7123 of 7207 vertices;
// first outside: vertex 12".
Status check_user_cage(const Eigen::MatrixXd& V, const Eigen::MatrixXd& C, Eigen::MatrixXi* CF,
                       double min_clearance = 1e-6);

}  // namespace mm
