// A compact linear basis of an animation's frames (PCA of the vertex displacements from a rest
// surface), for exporting long clips as a few morph targets plus per-frame weights instead of one
// morph target per frame (io/gltf_animation.h, MorphExport::Compact). Engineering, not paper 002.
//
// Convention: frame f is approximated by  X_f ≈ V_rest + mean + Σ_k weights(f, k) · component_k,
// where mean is the average displacement over the frames and the components are the leading
// principal directions of the centered displacements (ordered by decreasing variance; each
// component's sign is fixed so that its largest-magnitude coordinate is positive). The weights of
// each component have zero mean over the frames and the weight columns are mutually orthogonal.
//
// How: the F × 3n matrix D of centered displacements is never formed. Its F × F Gram matrix D·Dᵀ
// is accumulated over blocks of vertices (each block F × 3c, ≤ ~16 MB), eigen-decomposed
// (D·Dᵀ = V Λ Vᵀ), and component k = Dᵀ v_k / σ_k with weights σ_k v_k (a thin SVD of D by its
// Gram matrix). A second pass over the same blocks forms the components and the exact maximum
// vertex error for every number of components 0..K at once (residuals updated one rank at a time).
// Cost: F²·3n/2 (Gram) + ~4·F·3n·K flops, memory F² + 3n·K doubles plus one block.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct MorphBasisOptions {
  int max_components = 64;  // K at most (also ≤ #frames − 1 and ≤ the numerical rank of D)
  double block_bytes = 16e6;  // size of one block of displacements (vertices × frames) in memory
};

struct MorphBasis {
  Status status;                // InvalidArgument: no frames or a frame of the wrong shape / not finite
  Eigen::MatrixXd mean;         // #V by 3 mean displacement from V_rest
  Eigen::MatrixXd components;   // 3#V by K; column k is component k, row 3v + c is vertex v, coordinate c
  Eigen::MatrixXd weights;      // #frames by K
  Eigen::VectorXd sigma;        // K singular values of D (descending): ‖weights.col(k)‖
  Eigen::VectorXd max_error;    // K + 1: max over frames and vertices of the distance to the frame
                                // when only the first k components are used (max_error[0]: mean only)
};

// frames: per frame #V by 3 positions; V_rest: #V by 3.
MorphBasis morph_basis(const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXd& V_rest,
                       const MorphBasisOptions& opt = {});

// Smallest k with basis.max_error[k] ≤ tolerance, or -1 when no k reaches it.
int morph_basis_size(const MorphBasis& basis, double tolerance);

}  // namespace mm
