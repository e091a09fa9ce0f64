// Generalized eigenbasis W φ = λ A φ of the k smallest eigenpairs (Laplace–Beltrami
// "manifold harmonics"), with W the cotangent stiffness and A the lumped Voronoi mass
// (operators/operators.h; paper 000 Sec. 3 — its L = D⁻¹W is read as A⁻¹W, the sound form).
//
// Conventions:
// - eigenvalues ascending, λ₀ ≈ 0 (one zero per connected component);
// - eigenvectors A-orthonormal: Φᵀ A Φ = I;
// - sign: each φ is flipped so that Σᵢ aᵢ φᵢ (1 + i/n) > 0 (a fixed, index-based weight, so the
//   choice is deterministic and the constant eigenvector is positive). Vectors inside a
//   degenerate eigenspace are not unique: compare eigenvalues and projections, not raw vectors.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

struct SpectralBasisOptions {
  int k = 20;                 // number of eigenpairs; 1 ≤ k < #V
  int ncv = 0;                // Krylov subspace size; 0 = min(#V, max(2m + 1, m + 20)) with m
                              // the pairs asked for: k, more in a pass after missed eigenvalues
  double cluster_gap = 1e-6;  // τ of the completeness count = λ_{k-1} (1 + cluster_gap), at least
                              // |σ| above it (and below the next computed eigenvalue)
  double relative_shift = 1e-6; // σ = -relative_shift · tr(W)/tr(A): W - σA is SPD even though
                              // W is singular, and σ sits just below λ₀ = 0 for fast convergence
  double tolerance = 1e-10;   // Spectra's relative eigenvalue tolerance
  int max_iterations = 1000;  // Spectra restarts before NotConverged
};

struct SpectralBasis {
  Status status;
  Eigen::VectorXd eigenvalues; // k, ascending
  Eigen::MatrixXd vectors;     // #V by k, A-orthonormal columns
  int iterations = 0;          // Spectra restarts used
  int operations = 0;          // shift-invert solves performed
  int passes = 0;              // Lanczos runs: 1, or more when the inertia count found missed ones
  int missed = 0;              // eigenvalues the earlier passes missed (copies in multiplets)
};

// W: #V by #V cotangent stiffness (PSD), mass: #V lumped areas (all > 0).
SpectralBasis spectral_basis(const Eigen::SparseMatrix<double>& W, const Eigen::VectorXd& mass,
                             const SpectralBasisOptions& opt = {}, const Progress& progress = {});

// Convenience: assembles W and the Voronoi mass of (V, F) and calls the above.
// Fails with InvalidMesh if a vertex has zero area (unreferenced vertex or degenerate faces).
SpectralBasis spectral_basis(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const SpectralBasisOptions& opt = {}, const Progress& progress = {});

}  // namespace mm
