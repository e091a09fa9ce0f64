// LaplacianEditor: implicit Laplacian mesh editing with similarity transformations
// (Fu, Au, Tai — "Effective derivation of similarity transformations for implicit Laplacian mesh
// editing", paper 001, Sec. 3, 4, 6), as a precompute / drag / finalize session.
//
//   precompute(V, F, region)   stencils of the implicit deformation gradients M_i (Eq. 2–4),
//                              degenerate vertices (Sec. 3.3), assembly of E_L + E_R (Eq. 5–7),
//                              factorization of AᵀA (Sec. 6), the per-handle response basis, and
//                              the prefactored Poisson system of the finalize step (Eq. 9/10).
//   drag(transforms)           the fast preview: minimiser of Eq. 7 for new handle transforms.
//   finalize(mode)             shear removal by polar decomposition of every M_i (Sec. 4) and the
//                              second solve D(ṽ_i) = R_i δ_i (Eq. 9) or R_i S_i δ_i (Eq. 10).
//
// Per-coordinate separation (Sec. 6). M_i = Σ_k x̃_k w_kᵀ is linear in the unknowns and its row r
// only involves coordinate r (see edit/implicit_gradients.h). Hence row r of M_i δ_i, of
// M_i − M_j and of D(ṽ_i) involve coordinate r only, with the SAME coefficients for r = x, y, z:
// the least-squares matrix A is identical for the three coordinates and AᵀA (n_free by n_free,
// not 3n by 3n) is factored once; each drag is three back-substitutions (or cheaper, below).
//
// Handle response basis. Hard constraints are eliminated: x_free = (AᵀA)⁻¹(−Q x_known + …), which
// is linear in the known positions. When every handle moves by an affine map x ↦ A_h x + t_h, the
// result is x_free = rest + Σ_h Φ_h [(A_h − I) τ_h]ᵀ (τ_h = (A_h − I) c_h + t_h, c_h the handle's
// rest centroid) with Φ_h (n_free by 4) computed at precompute by 4 back-substitutions per handle. drag(transforms) then costs O(n_free · #handles) instead of a
// triangular solve; drag_positions() takes arbitrary per-vertex targets and does the 3
// back-substitutions. Both give the same result up to rounding (tested).
//
// Scaling. The paper adds E_L and E_R with equal weights but leaves their units open (E_L rows with
// cotangent weights divided by Voronoi areas are 1/length, E_R rows dimensionless). We make both
// dimensionless with the mean edge length h of the edited region, so the result does not depend
// on the mesh's scale or units; coherence_weight then multiplies E_R (paper: 1).
//
// Precision. Both stages are solved for displacements u = x − rest (rest = the displaced rest
// mesh in stage 1): the rest mesh is an exact solution of the homogeneous systems (M_i = I there,
// Eq. 4, and E_L, E_R vanish; D(v) = δ), so the identity edit is exact by construction and the
// right-hand sides carry only the change. The normal equations AᵀA of Eq. 7 square the
// condition number of A (a plain solve lost up to ~1e-6 of the diagonal on 20k-vertex meshes
// with thin parts and few small handles), so every solve is refined against the unsquared
// system: r = Aᵀ(b − A u) with A applied matrix-free (E_L rows stored, E_R and the gradient
// rows through the M_i), correction by the existing factor (linalg/iterative_refinement.h). The
// handle basis Φ is refined at precompute, so drag() stays a dense product; drag_positions()
// refines each solve, finalize() those of its least-squares (soft-constraint) system — with hard
// constraints its system is square and factored as is. Measured: identity and similarities on all constraints to
// ≤ 1e-9 of the diagonal (tests/edit_precision_test.cpp).
//
// Degenerate vertices (Sec. 3.3). Stage 1 runs on the rest mesh with Eq. 8 displacements; a
// displaced free vertex k is pulled back after the solve by ṽ_k = M_k (v_k − v'_k) + ṽ'_k. The
// finalize system (Eq. 9/10) runs on the undisplaced rest mesh, so degenerate vertices are solved
// in the least-squares sense like all others there (the paper's remark that this spreads the
// pull-back error over the ROI). Displaced constrained vertices get the handle transform of
// their displaced position in stage 1 and of their true position in the output.
//
// Known limits (measured, docs/edit.md): Eq. 9/10 only rotate Laplacian coordinates, which are
// zero on flat faces and sum to zero around a tube's cross-section, so a finalized bend is
// straighter than the stage-1 preview; and the linear coherence term blends rotations through
// shrunk matrices, so twists approaching π concentrate mid-way (the paper: use intermediate
// handles for large rotations).
//
// Errors (Status codes): InvalidArgument — empty handle set, index out of range, overlapping
// handle/fixed sets, no free vertex, wrong number of transforms, non-finite transforms or
// targets, a free region with no constraint; InvalidMesh — non-manifold or degenerate faces in the
// edited region, isolated vertices; FactorizationFailed; NumericalError (non-finite output);
// Cancelled (progress sink). Conventions of V/F: mesh/mesh.h; Laplacian sign: operators/operators.h.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

// x ↦ linear · x + translation, applied to a handle's rest positions.
struct HandleTransform {
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();  // rotation × uniform scale (any finite 3x3 accepted)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // mesh units

  // x ↦ pivot + translation + scale · R(axis, angle) · (x − pivot). angle in radians, axis any
  // non-zero vector (normalised here; a zero axis means no rotation), scale > 0.
  static HandleTransform similarity(const Eigen::Vector3d& translation, const Eigen::Vector3d& axis,
                                    double angle, const Eigen::Vector3d& pivot, double scale = 1.0);
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return linear * x + translation; }
};

struct EditRegion {
  // Vertices allowed to move. Empty = every vertex of the connected components that contain a
  // handle vertex ("ROI defaults to the whole component"). Vertices outside stay where they are.
  std::vector<int> roi;
  // One vertex list per handle (at least one non-empty handle; handles must not overlap).
  std::vector<std::vector<int>> handles;
  // Vertices pinned at their rest position (must not overlap a handle).
  std::vector<int> fixed;
};

enum class LaplacianWeights {
  Cotangent,  // w_ij = (cot α + cot β)/|Ω_i| (paper's choice; far better at degenerate vertices, Fig. 3e)
  Uniform,    // w_ij = 1/|N(i)|
};

enum class EditMethod {
  Implicit,        // paper 001: implicit deformation gradients + shear removal
  NaiveLaplacian,  // baseline: D(ṽ_i) = δ_i with unrotated Laplacian coordinates (for comparison)
};

// How finalize() rotates the Laplacian coordinates δ_i = Σ_j w_ij (v_i − v_j) in Eq. 9/10.
enum class RotatedCoordinates {
  // Each edge term by the mean of its two end vertices' similarities: D(ṽ_i) = Σ_j w_ij ½(T_i + T_j)(v_i − v_j).
  // Equals T_i δ_i wherever T is locally constant; where it varies, the difference carries the
  // bend of thin parts, which T_i δ_i cannot (on a tube the δ_i of a cross-section sum to ~0, so
  // T_i δ_i reconstructs a straight centre line between the handles). Measured in docs/edit.md:
  // bar bent 90°: rigidity error 0.067 vs 0.112 (PerVertex); slender cylinder 0.026 vs 0.140.
  PerEdge,
  PerVertex,  // D(ṽ_i) = T_i δ_i, Eq. 9/10 read literally
};

struct LaplacianEditOptions {
  EditMethod method = EditMethod::Implicit;
  LaplacianWeights weights = LaplacianWeights::Cotangent;  // D of Eq. 1 in both stages
  int coherence_rings = 2;        // SF of Eq. 6: pairs (i, j) within this many edges (paper: 2, footnote †); 1..3
  double coherence_weight = 1.0;  // weight of E_R relative to E_L after the scaling above (paper: 1); > 0
  double condition_threshold = 2e5;  // degenerate when cond(V_i V_iᵀ) exceeds this (Sec. 3.3: 2.0e5)
  double displacement_scale = 0.2;   // s_disp of Eq. 8 (paper: 0.2)
  RotatedCoordinates rotated_coordinates = RotatedCoordinates::PerEdge;  // finalize (Eq. 9/10), see above
  // PerEdge only: after the Eq. 9/10 solve, re-fit each free vertex's rotation to its finalized
  // 1-ring and solve again, this many times (one back-substitution each; the paper does 0). One
  // pass evens out rotations that stage 1 concentrated: bar bent 90° 0.067 → 0.061 rigidity
  // error, bar twisted 150° 0.121 → 0.106 and its 2 inverted faces gone. ≥ 0.
  int finalize_refinements = 1;
  // Eq. 7 transformation constraints M_c = W: every handle vertex's gradient is pulled towards its
  // handle's linear part, as extra least-squares rows of this weight (0 = off, paper's default
  // editing uses position constraints only). ≥ 0.
  double gradient_constraint_weight = 0.0;
  // 0 = hard position constraints, eliminated from the system (paper). > 0 = soft constraints on
  // handle and fixed vertices with this weight relative to E_L (dimensionless); vertices outside
  // the ROI stay hard. Soft constraints act in the Eq. 7 solve; the finalize system is square
  // (one Laplacian row per free vertex, one soft row per constrained one), so there they are met
  // exactly whatever the weight.
  double soft_constraint_weight = 0.0;
  // Precompute Φ_h so that drag() is a small dense product (4 back-substitutions per handle at
  // precompute). false: drag() does three back-substitutions like drag_positions().
  bool handle_basis = true;
  // Iterative refinement of the least-squares solves against the unsquared system (see
  // "Precision" above): at most this many correction steps after the first solve, each a
  // residual with A and a solve with the existing factor; the loop stops earlier once the
  // correction stops shrinking or the error left is below 1e-13 of the solution (typically after
  // one step). 0 = off (plain normal-equations solves). 0..10.
  int residual_refinements = 3;
};

enum class FeatureSize {
  Keep,   // Eq. 9: D(ṽ_i) = R_i δ_i — features keep their size (rigid handle moves)
  Scale,  // Eq. 10: D(ṽ_i) = R_i S_i δ_i, s_i = sqrt(mean of squared singular values of M_i)
};

struct EditStats {
  int free_vertices = 0;         // unknowns of the systems
  int known_vertices = 0;        // constrained vertices referenced by the systems
  int degenerate_vertices = 0;   // centers with cond(V_i V_iᵀ) > threshold on the input
  int displaced_vertices = 0;    // vertices moved by Eq. 8
  int widened_stencils = 0;      // valence < 3 centers whose stencil became the 2-ring
  int coherence_pairs = 0;       // |SF| used in E_R
  long system_nonzeros = 0;      // nnz of the lower triangle of AᵀA (stage 1)
  long factor_nonzeros = 0;      // entries stored in its supernodal Cholesky factor (incl. the
                                 // explicit zeros of relaxed supernodes)
  double max_condition = 0;      // max cond(V_i V_iᵀ) after the degenerate handling
  double mean_edge_length = 0;   // h, the scale of the edited region (mesh units)
  // Wall time of the precompute stages in ms (for bench/ and the CLI's --verbose; not deterministic).
  double stencil_ms = 0;         // Eq. 2–4 stencils and Sec. 3.3 degenerate handling
  double assembly_ms = 0;        // AᵀA of Eq. 7 (E_L + E_R)
  double factor_ms = 0;          // Cholesky of AᵀA
  double basis_ms = 0;           // handle response basis (4 back-substitutions per handle)
  double poisson_ms = 0;         // assembly + factor of the Eq. 9/10 system
  int basis_refinements = 0;     // iterative-refinement steps applied to the handle basis Φ
};

struct EditResult {
  Status status;      // check ok() before reading V
  Eigen::MatrixXd V;  // #V by 3 deformed positions of the whole mesh (finite)
  int refinements = 0;  // iterative-refinement steps of this call's solves (0 for a basis drag)
};

class LaplacianEditor {
 public:
  LaplacianEditor();
  ~LaplacianEditor();
  LaplacianEditor(LaplacianEditor&&) noexcept;
  LaplacianEditor& operator=(LaplacianEditor&&) noexcept;

  // V: #V by 3 rest positions; F: #F by 3. Builds and factors both systems for this (ROI,
  // handles, fixed) set; call again when the sets change. On failure the editor is empty.
  Status precompute(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const EditRegion& region,
                    const LaplacianEditOptions& opt = {}, const Progress& progress = {});
  bool ready() const;

  // Stage 1 (Eq. 7) for one transform per handle (in the order of EditRegion::handles). This is
  // the fast preview; it also records the gradients M_i that finalize() uses.
  // NaiveLaplacian method: the baseline solve D(ṽ) = δ.
  EditResult drag(const std::vector<HandleTransform>& transforms);
  // Stage 1 for arbitrary targets: rows of `targets` (#V by 3) at handle vertices are read,
  // others ignored. Three back-substitutions. With gradient constraints, each handle's linear
  // part is the best-fit similarity of its rest → target positions.
  // max_refinements: refinement steps for this call (-1 = options().residual_refinements). 0 is
  // the interactive preview — one plain normal-equations solve, like an LᵀL drag, off by
  // ~eps·cond(A)² (measured: 8e-9–5e-7 of the diagonal in tests/edit_precision_test.cpp, at most
  // 6.7e-5 on michael3's bench drag) — for the frames of a pointer drag; refine on release
  // (merge always refines).
  EditResult drag_positions(const Eigen::MatrixXd& targets, int max_refinements = -1);
  // Stage 2 after a drag: shear removal (Sec. 4) and Eq. 9 (Keep) / Eq. 10 (Scale).
  EditResult finalize(FeatureSize mode = FeatureSize::Keep);

  // M_i of the last drag as #V by 9 rows (row-major 3x3); identity rows for vertices without an
  // unknown in their stencil. Empty before the first drag (and for the naive method).
  Eigen::MatrixXd gradients() const;
  // Vertices displaced by Eq. 8 (ascending) and statistics of the precompute.
  const std::vector<int>& displaced_vertices() const;
  const EditStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct LaplacianEditResult {
  Status status;
  Eigen::MatrixXd V;        // #V by 3 result of finalize (or of drag when finalize = false)
  Eigen::MatrixXd preview;  // #V by 3 result of the stage-1 solve (Eq. 7)
  EditStats stats;
};

// One-shot convenience: precompute + drag(transforms) + finalize(mode).
LaplacianEditResult laplacian_edit(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                   const EditRegion& region, const std::vector<HandleTransform>& transforms,
                                   const LaplacianEditOptions& opt = {}, FeatureSize mode = FeatureSize::Keep,
                                   bool finalize = true, const Progress& progress = {});

}  // namespace mm
