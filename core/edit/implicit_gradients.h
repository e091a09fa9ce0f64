// Implicitly defined deformation gradients (paper 001 Sec. 3.1, Eq. 2–4) and the handling of
// degenerate vertices (Sec. 3.3, Eq. 8).
//
// For a center vertex i with stencil {i} ∪ N(i), Eq. 4 gives M_i = Ṽ_i V_iᵀ (V_i V_iᵀ)⁻¹, which is
// LINEAR in the unknown positions: M_i = Σ_k x̃_k w_kᵀ over the stencil entries k (x̃_k the 3-vector
// of deformed vertex k, w_k a constant 3-vector). Row r of M_i therefore only involves coordinate r
// of the unknowns, which is why the editing system separates per coordinate (paper Sec. 6).
// Properties (tests rely on them): Σ_k w_k = 0 (translations do not change M_i) and
// Σ_k v_k w_kᵀ = I at rest (M_i = I for the undeformed mesh, computed on the displaced rest mesh).
//
// Degenerate centers (cond(V_i V_iᵀ) > threshold: i and its neighbours (nearly) coplanar) are made
// regular by displacing a vertex out of the plane along its normal by s_disp × mean 1-ring edge length
// (Eq. 8); the displacement is undone after the solve (see laplacian_editor.h). Open-boundary
// variants of Sec. 3.3:
//  - neighbours collinear → one neighbouring non-boundary vertex is displaced instead of i;
//  - valence < 3 → the paper inserts a vertex at the midpoint of the opposite edge. We do not change
//    the mesh; instead the stencil of i is widened to its 2-ring (same purpose: a third direction,
//    still linear in the unknowns), then the usual displacement test runs on the widened stencil.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct ImplicitGradientOptions {
  double condition_threshold = 2e5;  // cond(V_i V_iᵀ) above this → degenerate (paper Sec. 3.3: 2.0e5); > 1
  double displacement_scale = 0.2;   // s_disp of Eq. 8 (paper: 0.2), fraction of the mean 1-ring edge length; > 0
};

struct ImplicitGradients {
  Status status;               // InvalidMesh when a center stays numerically singular (cond > 1e12)
  Eigen::MatrixXd V_displaced; // #V by 3: V with the Eq. 8 displacements applied (other rows equal V)
  std::vector<int> centers;    // vertices that have a gradient, ascending (as requested)
  std::vector<int> offsets;    // #centers+1: entries of center c are [offsets[c], offsets[c+1])
  std::vector<int> stencil;    // vertex index per entry; the first entry of a center is the center
  Eigen::MatrixXd weights;     // #entries by 3: w_k (row k of K_i)
  std::vector<int> degenerate; // centers found degenerate on the input (before displacement), ascending
  std::vector<int> displaced;  // vertices moved by Eq. 8, ascending
  std::vector<int> widened;    // centers whose stencil was widened to the 2-ring (valence < 3), ascending
  double max_condition = 0;    // largest cond(V_i V_iᵀ) over centers after the handling

  // M_i of center number c (index into `centers`) for positions X (#V by 3).
  Eigen::Matrix3d gradient(int c, const Eigen::MatrixXd& X) const;
};

// V: #V by 3; F: #F by 3; adjacency: vertex_adjacency(F, #V) (mesh/topology.h); centers: the
// vertices that need a gradient (any order; duplicates ignored). Normals for Eq. 8 are the
// area-weighted vertex normals of V (operators/operators.h).
ImplicitGradients implicit_gradients(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                     const std::vector<std::vector<int>>& adjacency,
                                     std::vector<int> centers,
                                     const ImplicitGradientOptions& opt = {});

}  // namespace mm
