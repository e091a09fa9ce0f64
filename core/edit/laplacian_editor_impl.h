// Internal to core/edit (not part of the public API): the state of LaplacianEditor and the
// pieces of its precompute, one concept per file (paper 001):
//   edit_region.cpp        ROI / handles / fixed bookkeeping, region checks, local numbering
//   similarity_system.cpp  stage 1: implicit similarity system, E_L + E_R (Eq. 5–7), its solve
//   handle_basis.cpp       per-handle response basis Φ for fast drags (Eq. 7 by superposition)
//   finalize_system.cpp    stage 2: Poisson system with rotated coordinates (Eq. 9/10), its solve
//   laplacian_editor.cpp   the public facade (precompute, drag, finalize)
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "edit/implicit_gradients.h"
#include "edit/laplacian_editor.h"
#include "linalg/supernodal_cholesky.h"

namespace mm {

namespace edit_detail {

using EditSparse = Eigen::SparseMatrix<double>;
using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
using EditTriplet = Eigen::Triplet<double>;

// Best-fit similarity linear part (s·R) mapping rest points P to targets Q (Umeyama 1991,
// linalg/rigid_fit.h). Fewer than 3 points, or collinear points, give the identity.
Eigen::Matrix3d edit_fit_similarity_linear(const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q);

// Non-manifold and degenerate-face checks restricted to the faces around the unknowns;
// `adjacency` = vertex_adjacency(F, #V).
Status edit_check_region_manifold(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const std::vector<int>& faces,
                                  const std::vector<char>& is_unknown, const std::vector<std::vector<int>>& adjacency);

// Milliseconds since `t0`; resets t0 to now.
double edit_lap_ms(std::chrono::steady_clock::time_point* t0);

// Scratch of one precompute, handed from piece to piece (global numbering unless said).
struct EditBuild {
  int n = 0;                               // #V
  std::vector<std::vector<int>> adj;       // vertex adjacency
  std::vector<int> gid;                    // per vertex: handle index, -1 fixed, -2 free
  std::vector<char> in_roi, unknown;       // per vertex
  std::vector<int> U;                      // unknowns, ascending
  std::vector<int> faces;                  // faces around the unknowns (complete 1-rings)
  bool soft_mode = false;                  // soft constraints (handles are unknowns too)
  double h = 0;                            // mean edge length around the unknowns
  bool implicit = false;                   // EditMethod::Implicit
  int r = 1;                               // coherence rings
  std::vector<int> pair_centers, active_centers;  // E_R centers (Eq. 6); gradient involves an unknown
  std::vector<char> is_active;             // per grads.centers entry
  std::vector<int> center_index;           // per vertex: index into grads.centers (-1 if none)
  std::vector<int> g2l;                    // global → local (-1 when not referenced)
  Eigen::MatrixXi Fsub;                    // rows of F listed in `faces`
  bool cot = true;                         // cotangent (else uniform) weights
  std::chrono::steady_clock::time_point clock;
};

}  // namespace edit_detail

struct LaplacianEditor::Impl {
  LaplacianEditOptions opt;
  Eigen::MatrixXd V, Vd;  // rest and displaced rest (#V by 3)
  int num_handles = 0;
  EditStats stats;

  // Local numbering: [0, nU) unknowns, [nU, nL) known vertices referenced by the systems.
  int nU = 0, nL = 0;
  std::vector<int> l2g;
  std::vector<int> group;   // per local vertex: handle index, -1 fixed/outside, -2 plain free unknown
  std::vector<double> soft; // per unknown: soft weight ws/h² (0 when not soft-constrained)
  std::vector<char> has_row;  // per unknown: carries a Laplacian row (not soft-constrained)

  ImplicitGradients grads;      // centers in global numbering
  std::vector<int> center_of;   // per local unknown: index into grads.centers (-1 if none)
  std::vector<int> stencil_local;  // grads.stencil mapped to local numbering (-1 outside)
  std::vector<int> displaced_unknowns;  // local unknowns displaced by Eq. 8

  // Stage 1 (Eq. 7): AᵀA has a 4-ring pattern; the supernodal factor is 2.5–4× faster there
  // than Eigen::SimplicialLDLT (measured at 14.6k and 52k vertices).
  SupernodalCholesky solver1;
  // The unsquared operator A of Eq. 7, kept for the residuals of iterative refinement: the E_L
  // rows as a matrix, the E_R and gradient-constraint rows through the stencils (they would be
  // ~17M entries at 50k vertices) and the pair graph.
  edit_detail::EditSparse E1;      // nU by nL: E_L rows (Eq. 5), scaled (zero rows without a Laplacian row)
  std::vector<int> pair_center;    // per E_R center p: index into grads.centers
  std::vector<char> pair_active;   // per p: its gradient involves an unknown
  std::vector<int> pair_handle;    // per p: handle of its gradient-constraint rows, -1 none
  std::vector<int> partner_ptr, partners;  // per p: its E_R partners (indices p), both directions
  std::vector<Eigen::Vector3d> handle_center;  // per handle: centroid of its displaced rest positions
  std::vector<Eigen::MatrixXd> Phi;  // per handle nU by 4: response to [(A_h − I) τ_h]ᵀ
  bool have_basis = false;

  // Stage 2 (Eq. 9/10) on the undisplaced mesh (1-ring pattern; supernodal solves are faster).
  SupernodalCholesky solver2;
  edit_detail::EditSparse D2_UU, D2_UK;  // hard: W_UU, W_UK; soft: row-scaled D rows of unknowns
  Eigen::MatrixXd LC;                // nU by 3: (W V)_i of the unknowns (rest Laplacian coordinates)
  // Edges of the unknowns for the per-edge right-hand side: unknown l owns entries
  // [edge_begin[l], edge_begin[l+1]) with the other end (local), w_ij of W and rest v_i − v_j.
  std::vector<int> edge_begin, edge_end_vertex;
  std::vector<double> edge_weight;
  std::vector<Eigen::Vector3d> edge_rest;
  Eigen::VectorXd row_scale2;        // soft mode: per-unknown row scale of D (2h/A_i or 1/(h·deg))

  // Last drag.
  bool have_drag = false;
  Eigen::MatrixXd U1;        // nL by 3: stage-1 displacements from the displaced rest mesh Vd
  Eigen::MatrixXd known;     // nK by 3: known positions in the original frame
  Eigen::MatrixXd soft_u;    // nU by 3: soft targets in the original frame (rows with soft > 0)
  std::vector<Eigen::Matrix3d> linear;  // per handle: linear part used by the last drag

  bool ready = false;

  // Precompute (laplacian_editor.cpp), in the order it calls them:
  Status build(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const EditRegion& region, const Progress& progress);
  // edit_region.cpp: inputs, handles, fixed and ROI → unknowns, region faces, checks; the scale h.
  Status build_region(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F, const EditRegion& region,
                      edit_detail::EditBuild* s);
  void region_edge_scale(const Eigen::MatrixXi& F, edit_detail::EditBuild* s);
  // similarity_system.cpp: implicit gradient stencils (Eq. 8 displacement), before numbering.
  Status build_stencils(const Eigen::MatrixXi& F, edit_detail::EditBuild* s, const Progress& progress);
  // edit_region.cpp: local numbering of unknowns and referenced known vertices.
  void number_locally(const Eigen::MatrixXi& F, edit_detail::EditBuild* s);
  // edit_region.cpp: the region's Laplacian rows W_i and the factor turning them into D_i.
  void laplacian_rows(const edit_detail::EditBuild& s, const Eigen::MatrixXd& P, edit_detail::EditSparse* Wout,
                      Eigen::VectorXd* dscale) const;
  // finalize_system.cpp: stage 2 operator and factor (Eq. 9/10).
  Status build_finalize_system(edit_detail::EditBuild& s, const Progress& progress);
  // similarity_system.cpp: stage 1 normal equations and factor (Eq. 5–7).
  Status build_similarity_system(edit_detail::EditBuild& s, const Progress& progress);
  // handle_basis.cpp: per-handle responses Φ (superposition of Eq. 7 solutions).
  Status build_handle_basis(edit_detail::EditBuild& s, const Progress& progress);

  // Aᵀ(b − A Y) of Eq. 7 for m columns at once (the same A for each column, Sec. 6). Y: nL by m
  // (unknowns, then known values); grad_rhs: per handle 3 by m right-hand side of its
  // gradient-constraint rows per stencil direction c (empty without gradient constraints);
  // soft_target: nU by m (rows with soft > 0 read; empty without soft constraints). nU by m.
  void stage1_normal_residual(const Eigen::MatrixXd& Y, const std::vector<Eigen::MatrixXd>& grad_rhs,
                              const Eigen::MatrixXd& soft_target, Eigen::MatrixXd* g,
                              bool unknowns_zero = false);
  // Sparsity of a residual from x = 0 (stage1_normal_residual's unknowns_zero; built on first use).
  struct ZeroStartLists {
    bool ready = false;
    std::vector<int> first, second;   // pairs (see residual_pairs)
    std::vector<int> rows;            // E_L rows that read a constrained vertex
    edit_detail::EditSparse E1U;      // those rows, unknowns' columns
  } zero_start;
  void build_zero_start_lists();
  // Stage 1 for known displacements u_K (nK by 3, displaced frame), soft target displacements
  // (nU by 3 or empty) and the handles' linear parts; with `translation`, by the handle basis.
  Status solve_stage1(const Eigen::MatrixXd& known_u, const Eigen::MatrixXd& soft_u_d,
                      const std::vector<Eigen::Matrix3d>& linear, const std::vector<Eigen::Vector3d>* translation,
                      int* refinements, int max_refinements = -1);
  EditResult output_stage1(int refinements);
  EditResult solve_stage2(bool use_rotations, FeatureSize mode);
  Eigen::Matrix3d gradient_local(int l) const;  // M of unknown l from U1 (I + Σ u_k w_kᵀ)
};

}  // namespace mm
