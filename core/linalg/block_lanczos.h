// Block Lanczos with thick restarts: the largest eigenpairs of a symmetric operator given only as
// Y = Op(X) on blocks of vectors (issue 18: the eigenbases' solver).
//
// Why our own and not Spectra's: with a shift-invert operator the Lanczos work outside the solves
// is full reorthogonalisation, O(n·m²) for a Krylov space of m vectors. Spectra does it one vector
// at a time with matrix–vector products, which stream the whole basis from memory twice per step
// (55 % of a k = 100 solve at 52k vertices was those products, 21 % the solves). On blocks of b
// vectors the same work runs as matrix–matrix products (the basis is read once per block), and
// the operator is applied to b right-hand sides at once, which a supernodal factor does at a
// fraction of b single solves.
//
// Method (Golub & Underwood 1977; thick restart as in Wu & Simon 2000, in block form):
//   Q = [X₀ X₁ …] orthonormal, Op X_j = X_{j-1} R_{j-1}ᵀ + X_j A_j + X_{j+1} R_j  (block recurrence),
//   each new block orthogonalised locally, then once against all of Q (a second pass when the
//   norm drops by more than 1/√2: Daniel–Gragg–Kaufman–Stewart), H = Qᵀ Op Q kept column by
//   column. Rayleigh–Ritz on H when the space is full: Ritz pair (θ, Q s) has the residual
//   ‖R_last · s_last‖ (s_last = its last b entries). Converged when ≤ tolerance · |θ| for the
//   nev largest; else the best `keep` Ritz vectors become the new start of Q (H diagonal there)
//   and the last residual block continues the recurrence.
// Deterministic: the start block comes from a fixed pseudo-random sequence; the same inputs give
// the same bits.
#pragma once

#include <functional>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct BlockLanczosOptions {
  int nev = 1;              // wanted eigenpairs (largest eigenvalues)
  int block = 0;            // b: vectors per block; 0 = clamp(nev / 12, 4, 8)
  int max_dim = 0;          // Krylov space before a restart (a multiple of b); 0 = 2·nev + 2b
  double tolerance = 1e-10; // residual ≤ tolerance · |θ| (Spectra's relative criterion)
  int max_restarts = 1000;
};

struct BlockLanczosResult {
  Status status;            // NotConverged after max_restarts; Cancelled if apply() said stop
  Eigen::VectorXd values;   // nev eigenvalues, descending
  Eigen::MatrixXd vectors;  // n by nev, orthonormal
  int applications = 0;     // vectors the operator was applied to
  int restarts = 0;
};

// apply(X, Y): Y = Op X for an n by b block (Y is resized by the caller to n by b); returns false
// to cancel. Op must be symmetric. Needs n ≥ max_dim + b (callers with small n solve densely).
BlockLanczosResult block_lanczos(int n, const std::function<bool(const Eigen::MatrixXd& X, Eigen::MatrixXd* Y)>& apply,
                                 const BlockLanczosOptions& opt);

}  // namespace mm
