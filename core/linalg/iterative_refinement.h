// Iterative refinement of a prefactored solve: x ← x + S(r(x)) until the correction stops
// shrinking, where r(x) is the residual computed with the ORIGINAL operator and S an approximate
// inverse (usually a Cholesky factor).
//
// Least squares min ||A x − b|| solved through the normal equations AᵀA x = Aᵀb: the factor of
// AᵀA has the condition number of A squared, so a plain solve loses ~eps·cond(A)² of |x|. With
// r(x) = Aᵀ(b − A x) formed from A itself (not from the assembled AᵀA) and S = (AᵀA)⁻¹ by the
// factor, each step multiplies the error by ~eps·cond(A)², and the iteration stops at the accuracy
// of the residual, ~eps·cond(A)·|x| (Björck, "Numerical methods for least squares problems",
// Sec. 2.9; Higham, "Accuracy and stability of numerical algorithms", Ch. 12 and 20). The same
// loop refines square systems (r = b − A x).
//
// Stopping: the first solve (from x = 0, or the caller's x) is always applied; a refinement step
// is applied only if its correction is smaller than the previous one. The loop stops when a
// correction shrank by less than half (the residual's rounding is reached), when the residual is
// exactly zero (e.g. the identity edit in displacement form: no solve is paid for), when the
// error left — estimated as the last correction times the observed contraction rate (the ratio
// of the last two corrections) — is below 1e-13 of max |x|, or after max_steps. Typically: one
// refinement step for normal equations with cond(A)² ~ 1e10, then the estimate stops the loop.
#pragma once

#include <functional>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct IterativeRefinementReport {
  Status status;          // NumericalError when the first solve is not finite
  int steps = 0;          // refinement steps applied after the first solve
  double first = 0;       // max |entry| of the first solve's result (its correction from x)
  double last = 0;        // max |entry| of the last applied correction
};

// residual(x, &r): r = the right-hand side of the correction equation at x (same shape as x).
// solve(&r): r ← S r in place. x: in/out (its shape is kept; zero it for a plain solve first).
// max_steps ≥ 0 extra steps (0: a plain solve).
IterativeRefinementReport refine_solution(const std::function<void(const Eigen::MatrixXd&, Eigen::MatrixXd*)>& residual,
                                          const std::function<void(Eigen::MatrixXd*)>& solve, Eigen::MatrixXd* x,
                                          int max_steps);

}  // namespace mm
