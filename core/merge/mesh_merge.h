// Mesh merging with the implicit Laplacian editor (paper 001 Sec. 5, 6).
//
// A target mesh stays fixed; a source mesh is deformed so that chosen boundary loops of it land
// on chosen boundary loops of the target, then the two are zipped into one watertight mesh.
//
//   Configuration-independent (Sec. 5.1): the source may sit anywhere, at any orientation and
//     scale. Every source boundary vertex gets a target position on the target loop (arc-length
//     parameterization between user key pairs) and a deformation-gradient constraint
//     M_i = R_i S_i (R_i maps its local frame — boundary tangent, normal, their cross product —
//     to the frame at its target position; s_i is the ratio of tangent lengths). The whole
//     source is the ROI; Eq. 7 with those position and transformation constraints, then shear
//     removal and Eq. 10 (features scaled). The result is the same for every similarity applied
//     to the source.
//   Configuration-dependent (Sec. 5.2): the user placed the source. The boundary frames are kept
//     (R_i = I), only boundary positions and scales move; user handles on the source stay fixed;
//     the ROI is a band of geodesic width `roi_width` from the source boundary, and vertices
//     outside it keep their exact coordinates.
//   Boundary refinement (Sec. 6): a source loop with far fewer vertices than its target loop
//     has its boundary edges split first (longest first), so the boundary condition has the
//     target's resolution.
//   Zipping ([SLCO*04], Sec. 5.1): the band of target triangles touching the target loop is
//     removed and the gap between the target's new boundary and the deformed source boundary is
//     re-triangulated by advancing along both curves; a few umbrella-operator iterations [Tau95]
//     smooth the seam.
//
// Several boundary pairs may be merged at once (Fig. 11: one source into several target loops).
// Sources of any genus; source components without a merged loop are copied unchanged.
//
// Output vertex order: the target's vertices that remain (in input order), then the source's
// (in input order, then the vertices boundary refinement added). Faces: target faces that remain,
// source faces, zip faces.
//
// Errors: InvalidArgument (no pair; fewer than two keys; a key vertex out of range or not on the
// pair's boundary; keys on different loops; keys out of order along either loop; two pairs on the
// same loop; bad options), InvalidMesh (a mesh without boundary; a loop with fewer than 3
// vertices; the band next to a target loop cannot be removed cleanly), and the editor's errors
// (FactorizationFailed, NumericalError), Cancelled.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"
#include "edit/laplacian_editor.h"

namespace mm {

enum class MergeMode {
  ConfigurationIndependent,  // Sec. 5.1
  ConfigurationDependent,    // Sec. 5.2
};

// One merged pair of boundaries. Loops are found from the key vertices (the loop that contains
// them); `target_loop` / `source_loop` (indices into boundary_loops() of each mesh) may name the
// loop explicitly instead, and must then contain the keys.
struct MergeBoundaryPair {
  std::vector<int> target_keys;  // key vertices on the target loop, in order along the seam
  std::vector<int> source_keys;  // their partners on the source loop (same count, ≥ 2)
  int target_loop = -1;
  int source_loop = -1;
};

struct MergeOptions {
  MergeMode mode = MergeMode::ConfigurationIndependent;
  // The editing session (paper defaults). Its gradient_constraint_weight carries the boundary
  // deformation gradients M_c = W (Eq. 7); handle_basis is turned off (one handle per boundary
  // vertex would make the basis cost more than the solve).
  LaplacianEditOptions editor;
  double gradient_weight = 1.0;  // weight of the M_c = W rows of Eq. 7 (dimensionless); > 0
  // Sec. 6: refine the source loop when the target loop has more than this many times as many
  // vertices (then split its edges until it has at least as many as the target loop), so the
  // boundary condition has the target's resolution and the zip joins curves of similar spacing.
  // ≥ 1; 0 = off.
  double refine_ratio = 1.25;
  // Zip: number of umbrella iterations [Tau95] on the vertices within `smoothing_rings` of the
  // seam, and the step of each (x += step · (mean of neighbours − x)).
  int smoothing_iterations = 3;
  int smoothing_rings = 2;
  double smoothing_step = 0.5;
  // Configuration-dependent mode: ROI = source vertices whose geodesic distance to the source
  // boundary is below roi_width × the source's bounding-box diagonal. (0, ∞].
  double roi_width = 0.25;
  // Transition regions (Sec. 5.3, merge/transition.h): widths of the blended band on each side of
  // the seam, × the target's bounding-box diagonal. Both > 0 turns them on (the umbrella
  // smoothing still runs after them); 0 = off.
  double transition_target_width = 0;
  double transition_source_width = 0;
  bool zip = true;  // false: return the deformed source and the untouched target side by side
};

struct MergeSeamReport {
  int zip_faces = 0;          // triangles created across the gap
  int removed_faces = 0;      // target band faces removed
  double min_angle_deg = 0;   // smallest corner angle of the zip triangles
  double dihedral_max_deg = 0;   // largest angle between normals of faces sharing a seam edge
  double dihedral_mean_deg = 0;  // mean of it
  int flipped_faces = 0;      // zip triangles whose normal opposes their neighbours'
};

struct MergeStats {
  int source_vertices = 0, target_vertices = 0;
  int refined_vertices = 0;   // vertices added to source loops by Sec. 6 refinement
  int boundary_constraints = 0;
  double precompute_ms = 0, solve_ms = 0, zip_ms = 0;
  EditStats editor;
  std::vector<MergeSeamReport> seams;  // one per pair (empty when zip = false)
  int transition_vertices = 0;         // vertices rebuilt by the transition regions
};

struct MergeResult {
  Status status;
  Eigen::MatrixXd V;  // merged mesh
  Eigen::MatrixXi F;
  Eigen::MatrixXd source_deformed;  // #source vertices (after refinement) by 3
  Eigen::MatrixXi source_F;         // source faces after refinement
  std::vector<int> target_map;      // per target vertex: index in V, or -1 when removed by the zip
  int source_offset = 0;            // source vertex i is V.row(source_offset + i)
  MergeStats stats;
};

struct MergeInput {
  Eigen::MatrixXd target_V, source_V;
  Eigen::MatrixXi target_F, source_F;
  std::vector<MergeBoundaryPair> pairs;
  std::vector<int> source_fixed;  // configuration-dependent mode: source vertices kept in place
};

MergeResult merge_meshes(const MergeInput& in, const MergeOptions& opt = {}, const Progress& progress = {});

// Splits the longest boundary edges of `loop` (at their midpoints, the adjacent face split in
// two) until the loop has at least `min_vertices` vertices. Updates V, F and *loop (which stays
// in its order). Returns the number of vertices added.
int refine_boundary_loop(Eigen::MatrixXd* V, Eigen::MatrixXi* F, std::vector<int>* loop, int min_vertices);

}  // namespace mm
