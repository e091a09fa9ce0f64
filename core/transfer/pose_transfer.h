// Spectral pose transfer (Yin, Li, Lu, Ouyang, Zhang, Xian, "Spectral pose transfer", CAGD 2015
// = paper 000, Sec. 3–4.2): the source mesh takes the pose of the reference mesh and keeps its
// own details. The meshes may have different connectivity and proportions; landmark pairs tie
// them together (not needed for same-connectivity pairs).
//
// Pipeline (each stage reports progress and can be cancelled):
//  1. normalization: each mesh is centred at its area-weighted centroid and scaled to unit
//     surface area, so eigenfunctions and coefficients of both speak the same units;
//  2. eigenbases: the first k' generalized eigenpairs W φ = λ A φ of each mesh (paper 000 writes
//     L = D⁻¹W with D = diag(1/aᵢ); the sound reading is A⁻¹W, solved as Wφ = λAφ);
//  3. coupling: landmark functions (spectral/landmarks.h) and coupled quasi-harmonic bases
//     (spectral/coupled_bases.h), with the functional matrix Γ;
//  4. cage: automatic enclosing cage (cage/enclosing_cage.h) or the user's cage;
//  5. mean-value coordinates Ψ of the source in its cage (V = ΨC);
//  6. optimisation: the cage pose energy of Eq. 12 (transfer/cage_pose_solver.h) with the
//     reference's first K+1 coupled coefficients α' as targets; Ṽ = Ψ C̃.
// Baselines (method option): Lévy 2006 replaces the first K+1 coefficients in the plain
// eigenbases (Eq. 4; reference eigenvector signs matched to the source through the landmark
// functions), Kovnatsky 2013 does the same in the coupled bases (no cage, no optimisation).
//
// Output placement: the result has the source's surface area (its size) and sits at the
// reference's centroid (or the source's, `placement`); its orientation is the reference's,
// which is part of the pose that the low frequencies carry.
//
// Status codes: InvalidMesh (empty, non-finite or too coarse meshes, zero-area vertices),
// InvalidArgument (bad options or landmarks: out of range, too few, repeated, missing for a
// different-connectivity pair), NotConverged (eigensolver), NumericalError, Cancelled.
// Non-manifold input (e.g. camel_ref's 26 non-manifold edges and flipped faces) is accepted:
// every stage needs only triangles with positive area.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "cage/enclosing_cage.h"
#include "common/progress.h"
#include "common/status.h"
#include "mesh/mesh.h"
#include "spectral/coupled_bases.h"
#include "spectral/landmarks.h"
#include "transfer/cage_pose_solver.h"

namespace mm {

enum class TransferMethod {
  Yin,        // paper 000: deformation in the cage subspace with low frequencies as handles
  Kovnatsky,  // coefficient swap (Eq. 4) in coupled quasi-harmonic bases
  Levy,       // coefficient swap (Eq. 4) in plain Laplace–Beltrami eigenbases
};
const char* transfer_method_name(TransferMethod m);  // "yin", "kovnatsky", "levy"
bool parse_transfer_method(const std::string& name, TransferMethod* m);

enum class TransferPlacement {
  Reference,  // result centred where the reference is (compare directly with a ground truth)
  Source,     // result centred where the source is
};

// The automatic cage for pose transfer: EnclosingCageOptions with target_vertices = 450 (paper
// 000's Fig. 1 cage has 452 vertices; Table 1: 166–520). With 300 the cat-01/lion-01/cat-05
// transfers stay further from the reference pose (docs/transfer.md has the measurements).
inline EnclosingCageOptions pose_transfer_cage_options() {
  EnclosingCageOptions o;
  o.target_vertices = 450;
  return o;
}

struct PoseTransferOptions {
  TransferMethod method = TransferMethod::Yin;
  int num_low_frequencies = 5;   // K: coefficients 0..K are transferred (paper 000 Sec. 4.2: K = 5)
  int num_eigenpairs = 20;       // k': eigenpairs per mesh combined into the coupled bases
  CoupledBasesOptions coupling;  // k (num_coupled = 10 ≥ K+1), μ, convergence test
  LandmarkOptions landmarks;     // ring sizes, minimum count, generated count
  EnclosingCageOptions cage = pose_transfer_cage_options(); // automatic cage, ~450 vertices (below)
  CagePoseOptions solver;        // λ₁ = λ₂ = 0.05, re-linearization tolerance
  TransferPlacement placement = TransferPlacement::Reference;
  // With a given cage (part transfer reuses the level before's deformed cage): the cage vertices
  // that matter least to the source keep their positions during the optimisation (paper 000
  // Sec. 5: "we always fix those cage vertices that are far away from the part to be
  // processed"). A cage vertex's weight is Σ_i a_i |Ψ_ij| over the source's vertices (area a_i);
  // the lightest vertices whose weights add up to at most this fraction of the total are held.
  // 0: every cage vertex is free.
  double fixed_cage_weight = 0;
  // No folds at the whole-body step (issue 16): when the result in the automatic cage flips faces
  // against the source, or has more self-intersecting triangle pairs than the reference and the
  // source together, the cage is built again on this finer offset grid (cells along the longest
  // side) and the optimisation runs again; the result with fewer violations (flipped faces plus
  // self-intersecting pairs beyond that bound) is kept. The cause (docs/transfer.md, "Folds at
  // level 1"): on the 80-cell grid, decimation to 450 vertices bridges the gap between a pair of
  // legs, the legs then share cage vertices, and the optimisation pulls the feet into each other
  // (horse0 → camel_ref: 366 pairs against 293 allowed). 0 (or ≤ cage.resolution): no check —
  // the part transfers' own calls, which the part gate checks instead.
  int fold_retry_resolution = 128;
  // No flips: when the result (after the retry above) still flips faces against the source, the
  // flipped faces' neighbourhood, grown by this many edge rings, is relaxed as rigidly as possible
  // towards the source's shape with everything else held (transfer/flip_repair.h); kept when it
  // leaves fewer violations. 0: off (the part transfers' own calls; part_transfer repairs its
  // final result instead).
  int flip_repair_rings = 2;
};

// Folds of a transfer result (issue 16): self-intersecting triangle pairs (spatial/
// self_intersections.h) of the reference, the source and the result, and locally flipped faces
// of the result against the source (metrics/transfer_metrics.h).
struct FoldReport {
  int self_intersections_reference = 0;  // intersecting triangle pairs of the reference
  int self_intersections_source = 0;     // ... of the source (input)
  int self_intersections_result = 0;     // ... of the result
  int flipped_faces = 0;                 // result's local fold-overs against the source
  int collapsed_faces = 0;               // result's faces crushed below 1e-3 of their area (not flipped)
  int faulty_faces() const { return flipped_faces + collapsed_faces; }
  bool new_folds() const {               // more self-intersections than the inputs together
    return self_intersections_result > self_intersections_reference + self_intersections_source;
  }
  // Flipped and collapsed faces plus the self-intersecting pairs beyond the inputs' count (0 = no
  // fold).
  int violations() const {
    return faulty_faces() +
           std::max(0, self_intersections_result - self_intersections_reference - self_intersections_source);
  }
};

// reference: #V′ mesh; source: the input source; result: #V_source by 3 positions.
FoldReport fold_report(const Mesh& reference, const Mesh& source, const Eigen::MatrixXd& result);
// The same for another result of the same inputs: their counts are taken from `inputs`.
FoldReport fold_report(const FoldReport& inputs, const Mesh& source, const Eigen::MatrixXd& result);

// What PoseTransferOptions::fold_retry_resolution did.
struct FoldRetry {
  bool checked = false;  // the result's folds were counted (PoseTransferResult::folds is valid)
  bool tried = false;    // the first result folded: the cage was built again on the finer grid
  bool kept = false;     // ... and that result had fewer violations, so it is the one returned
  int resolution = 0;    // the finer grid's cells along the longest side
  FoldReport first;      // the folds of the first result (valid when tried)
  double ms = 0;         // time of the second cage, coordinates and optimisation
};

// What PoseTransferOptions::flip_repair_rings did (transfer/flip_repair.h).
struct FlipRepair {
  bool tried = false;       // the result flipped faces: the repair ran
  bool kept = false;        // ... and its result had fewer violations, so it is the one returned
  int flipped_before = 0;   // flipped faces before the repair
  int collapsed_before = 0; // collapsed faces (not flipped) before the repair
  int moved_vertices = 0;   // vertices the kept repair moved
  int rounds = 0;           // regions tried
  double ms = 0;
};

// Runs the repair on `result` when `folds` counts flipped faces (and rings > 0): replaces result
// and folds when the repaired result has fewer violations. Cancelled status on cancel.
Status repair_transfer_flips(const Mesh& source, int rings, const Progress& progress, Eigen::MatrixXd* result,
                             FoldReport* folds, FlipRepair* record);

struct PoseTransferTimings {     // wall-clock milliseconds per stage (informational)
  double eigenbases = 0, coupling = 0, cage = 0, mvc = 0, optimisation = 0, total = 0;
  // Natively the cage and MVC stages overlap the eigenbases and coupling (second thread), so
  // the stages can add up to more than the total.
};

struct PoseTransferResult {
  Status status;                   // see header
  Eigen::MatrixXd V;               // #V_source by 3: the source in the reference's pose
  std::vector<LandmarkPair> landmarks; // pairs used (generated ones for same connectivity)
  Eigen::MatrixXd gamma;           // k by k functional matrix of the bases used (coupled or plain)
  double gamma_dominance = 0;      // min_i |Γ_ii| / Σ_{j≠i}|Γ_ij| over the first K+1 rows
  int coupling_iterations = 0;     // coupled-bases gradient steps
  bool coupling_converged = false;
  Eigen::MatrixXd cage_rest;       // #C by 3 cage in source coordinates (Yin only)
  Eigen::MatrixXd cage_deformed;   // #C by 3 deformed cage, output coordinates (Yin only)
  Eigen::MatrixXi cage_faces;      // cage triangles
  int fixed_cage_vertices = 0;     // cage vertices held by fixed_cage_weight (Yin only)
  int iterations = 0;              // re-linearizations of the cage solve (Yin only)
  bool converged = true;           // cage solve reached its tolerance (Yin only)
  std::vector<double> energy;      // Eq. 12 energy after each iteration (Yin only)
  double energy_lf = 0, energy_lc = 0, energy_sf = 0; // final unweighted terms (Yin only)
  FoldReport folds;                // the result's folds, when fold_retry.checked
  FoldRetry fold_retry;            // Yin with the automatic cage and fold_retry_resolution set
  FlipRepair flip_repair;          // flip_repair_rings: what the repair did (when folds were checked)
  PoseTransferTimings ms;
};

// reference: the mesh whose pose is copied; source: the mesh that takes it. landmarks: pairs
// (reference vertex, source vertex); may be empty when both meshes have the same faces (then
// opt.landmarks.auto_count farthest-point landmarks are used). user_cage: optional closed cage
// around the source (null = automatic).
PoseTransferResult pose_transfer(const Mesh& reference, const Mesh& source,
                                 const std::vector<LandmarkPair>& landmarks,
                                 const PoseTransferOptions& opt = {}, const Progress& progress = {},
                                 const Mesh* user_cage = nullptr);

}  // namespace mm
