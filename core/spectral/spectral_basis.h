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

#include <string>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

// The Lanczos behind the shift-invert solve: our block Lanczos (linalg/block_lanczos.h: blocks of
// solves through the supernodal factor, reorthogonalisation as matrix–matrix products) or Spectra's
// one-vector Lanczos through SimplicialLDLT (the peer's configuration). Auto picks by the size of
// the Krylov basis, n·(2k + 1) doubles: Spectra's matrix–vector reorthogonalisation is fast while
// the basis stays in the last-level cache, and memory-bound beyond it, where the block solver's
// matrix–matrix products win despite needing ~1.5× the solves (docs/bench.md, thirteenth session:
// k = 100 at 52k vertices 5.5 → 2.8 s; at 11k, a 18 MB basis, Spectra 0.45 s vs block 0.6 s).
enum class EigenSolverKind { Auto, BlockLanczos, Spectra };

// "auto" | "block" | "spectra" (the CLI's --solver, the wasm option); false for anything else.
bool parse_eigen_solver(const std::string& name, EigenSolverKind* kind);

struct SpectralBasisOptions {
  int k = 20;                 // number of eigenpairs; 1 ≤ k < #V
  EigenSolverKind solver = EigenSolverKind::Auto;
  double block_min_basis_mib = 20;  // Auto: block Lanczos when n·(2k + 1)·8 bytes exceed this many MiB.
                                    // The same everywhere, so every build and thread count runs the
                                    // same solver (in single-threaded wasm, without SIMD products, the
                                    // crossover is later: 19k vertices, k = 100: block 2.09 s, Spectra 1.89 s)
  int block = 0;              // block Lanczos: vectors per block (0 = clamp(m / 12, 4, 8))
  int ncv = 0;                // Krylov subspace size before a restart; 0 = min(#V, max(2m + 1, m + 20))
                              // for Spectra, 2m + 2b for block Lanczos, with m the pairs asked for:
                              // k, more in a pass after missed eigenvalues. Meshes of at most
                              // dense_max_vertices (or too small for the Krylov space) are solved densely.
  int dense_max_vertices = 400;
  double cluster_gap = 1e-6;  // τ of the completeness count = λ_{k-1} (1 + cluster_gap), at least
                              // |σ| above it (and below the next computed eigenvalue)
  double relative_shift = 1e-6; // σ = -relative_shift · tr(W)/tr(A): W - σA is SPD even though
                              // W is singular, and σ sits just below λ₀ = 0 for fast convergence
  double tolerance = 1e-10;   // relative residual of each Ritz pair (Spectra's criterion, both solvers)
  int max_iterations = 1000;  // restarts before NotConverged
};

struct SpectralBasis {
  Status status;
  Eigen::VectorXd eigenvalues; // k, ascending
  Eigen::MatrixXd vectors;     // #V by k, A-orthonormal columns
  int iterations = 0;          // restarts used (0 for a dense solve)
  int operations = 0;          // shift-invert solves performed (right-hand sides)
  int passes = 0;              // Lanczos runs: 1, or more when the inertia count found missed ones
  const char* solver = "";     // which ran: "block Lanczos", "Spectra" or "dense"
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
