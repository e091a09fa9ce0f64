// Flip repair: the flipped faces of a deformed mesh re-solved from their surroundings
// (issue 16, "no folds"; not a step of paper 000).
//
// A transfer result can fold a few faces over their neighbours (metrics/transfer_metrics.h's
// flipped faces: a face whose normal opposes its neighbours' in the result while it agrees in
// the rest shape). The region around them — the flipped faces' vertices grown by `rings` edge
// rings — is solved again with every vertex outside it held, two ways, with the rest shape's
// cotangent weights:
// - detail: Laplacian editing with one rotation per connected piece of the region (the rigid
//   motion of the held band around it), which keeps the rest shape's detail turned like its
//   surroundings;
// - membrane: the smooth surface spanning the held positions, for where the rest detail does not
//   fit between them (a folded result is usually compressed there).
// The solve leaving fewer faulty faces — flipped or collapsed (a patch crushed to a sheet, which
// a membrane spanning a protrusion produces: michael9 → michael3's foot, 3,459 faces below 1e-3
// of their area when only flips were counted) — is kept (detail on a tie). A round that still
// leaves faulty faces is followed by one around those with twice the rings; a round is kept only
// when it leaves fewer, so the input comes back unchanged when none helps.
//
// Measured against a rotation per vertex (as-rigid-as-possible, Sorkine and Alexa 2007): on
// lion-07's level-1 result ARAP left 5 of 5 flipped faces at any iteration count (it buckles the
// compressed region again); detail / membrane: 5 → 0, error to the ground truth 0.11533 → 0.11544.
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"
#include "mesh/mesh.h"

namespace mm {

struct FlipRepairOptions {
  int rings = 2;   // region: the flipped faces' vertices grown by this many edge rings
  int rounds = 4;  // regions tried, each around the faces still flipped, with twice the rings
  int band = 2;    // rings of held vertices around a piece of the region that give its rotation
};

struct FlipRepairResult {
  Status status;            // Cancelled, or an error from the region's factorisation
  Eigen::MatrixXd V;        // the repaired positions (the input when nothing improved)
  int flipped_before = 0;   // flipped faces of the input
  int flipped_after = 0;    // ... of V
  int collapsed_before = 0; // collapsed faces (metrics/transfer_metrics.h) of the input, not flipped
  int collapsed_after = 0;  // ... of V
  int faulty_before() const { return flipped_before + collapsed_before; }
  int faulty_after() const { return flipped_after + collapsed_after; }
  int rounds = 0;           // rounds run
  int detail_rounds = 0;    // rounds kept with the rest shape's detail (the others: membrane)
  int moved_vertices = 0;   // vertices whose positions changed
  double ms = 0;
};

// rest: the mesh's rest shape (faces and positions); deformed: #V by 3 positions over rest.F.
FlipRepairResult repair_flips(const Mesh& rest, const Eigen::MatrixXd& deformed, const FlipRepairOptions& opt = {},
                              const Progress& progress = {});

}  // namespace mm
