// Coupled quasi-harmonic bases (Kovnatsky, Bronstein, Bronstein, Glashoff, Kimmel,
// "Coupled quasi-harmonic bases", Eurographics 2013), as used by paper 000 Sec. 3–4.
//
// Given the first k' generalized eigenpairs (W φ = λ A φ, spectral/spectral_basis.h) of the
// source (Φ, Λ) and the reference (Ψ, Λ'), and p corresponding functions F (source) and
// G (reference) (spectral/landmarks.h), find Φ̂ = Φ X and Ψ̂ = Ψ Y with X, Y ∈ St(k', k)
// (k' by k, orthonormal columns, so Φ̂ and Ψ̂ stay A-orthonormal) minimising
//     off(Xᵀ Λ X) + off(Yᵀ Λ' Y) + (μ / p) ‖Fᵀ A Φ X − Gᵀ A' Ψ Y‖²_F,
// off(M) = Σ_{i≠j} M_ij². Λ and Λ' are both divided by the largest of the 2k' eigenvalues
// so the "quasi-harmonic" terms are O(1) whatever the meshes' sizes; the coupling term compares
// region means of the basis functions (the landmark functions are area-normalized).
//
// Optimisation: Riemannian gradient descent on St(k', k) × St(k', k) (embedded metric,
// projected gradient G − X sym(Xᵀ G)), QR retraction with positive diag(R), Armijo
// backtracking with step growth. Convergence test (documented contract): stop when the norm of
// the Riemannian gradient is below `tolerance` × its initial norm, or when the energy decreased
// by less than tolerance × energy over the last 10 iterations; `converged` is false when
// max_iterations ran out instead (the bases are still valid and returned).
//
// Deterministic initialisation: X = I (source order). Y is a signed permutation: reference
// eigenvectors are greedily matched to source eigenvectors by the correlation of their
// landmark coefficients (only within `match_window` positions, largest |correlation| first,
// ties by index), with the sign of the correlation — eigenvector signs and the order of close
// eigenvalues differ between meshes, and gradient descent cannot flip a sign.
//
// Output order: pairs sorted by their mean normalized Rayleigh quotient (ascending), so the
// first K+1 columns are the low frequencies used by pose transfer.
//
// Functional matrix Γ (k by k): least-squares map from source to reference coefficients of the
// landmark functions, Γ = Ĝ Fᵀ̂ (F̂ F̂ᵀ)⁻¹ with F̂ = Φ̂ᵀ A F, Ĝ = Ψ̂ᵀ A' G. Coupled bases make
// Γ ≈ I; `diagonal_dominance` = min over the first `dominance_rows` rows of
// |Γ_ii| / Σ_{j≠i} |Γ_ij| (> 1 means diagonally dominant).
#pragma once

#include <Eigen/Core>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct CoupledBasesOptions {
  int num_coupled = 10;       // k: coupled functions returned (≥ K+1 = 6 for pose transfer)
  double mu = 1.0;            // weight of the coupling term (see normalization above)
  int match_window = 4;       // initial matching: |i − j| ≤ this between eigenvector indices
  int max_iterations = 1000;  // gradient steps before giving up (converged = false)
  double tolerance = 1e-6;    // convergence test, see header
  int dominance_rows = 6;     // rows of Γ checked for diagonal dominance (K+1)
};

struct CoupledBases {
  Status status;                  // InvalidArgument for inconsistent sizes
  Eigen::MatrixXd source;         // #V by k  Φ̂ (A-orthonormal)
  Eigen::MatrixXd reference;      // #V' by k Ψ̂ (A'-orthonormal)
  Eigen::MatrixXd X, Y;           // k' by k combination matrices (Φ̂ = Φ X, Ψ̂ = Ψ Y)
  Eigen::MatrixXd gamma;          // k by k functional matrix, see header
  double diagonal_dominance = 0;  // see header
  double energy_initial = 0, energy_final = 0;
  int iterations = 0;
  bool converged = false;
};

// Phi_*: #V by k' A-orthonormal eigenvectors with eigenvalues lambda_* (k', ascending);
// mass_*: lumped areas; F_source / F_reference: #V by p / #V' by p corresponding functions.
CoupledBases coupled_bases(const Eigen::MatrixXd& Phi_source, const Eigen::VectorXd& lambda_source,
                           const Eigen::VectorXd& mass_source, const Eigen::MatrixXd& F_source,
                           const Eigen::MatrixXd& Phi_reference, const Eigen::VectorXd& lambda_reference,
                           const Eigen::VectorXd& mass_reference, const Eigen::MatrixXd& F_reference,
                           const CoupledBasesOptions& opt = {}, const Progress& progress = {});

// Γ and its diagonal dominance for given bases (used for the plain eigenbases too).
void functional_matrix(const Eigen::MatrixXd& coeff_source, const Eigen::MatrixXd& coeff_reference, int rows,
                       Eigen::MatrixXd* gamma, double* dominance);

}  // namespace mm
