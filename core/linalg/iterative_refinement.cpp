#include "linalg/iterative_refinement.h"

#include <cmath>

namespace mm {

namespace {
constexpr double kRefinementTolerance = 1e-13;  // relative to max |x|
}  // namespace

IterativeRefinementReport refine_solution(const std::function<void(const Eigen::MatrixXd&, Eigen::MatrixXd*)>& residual,
                                          const std::function<void(Eigen::MatrixXd*)>& solve, Eigen::MatrixXd* x,
                                          int max_steps) {
  IterativeRefinementReport rep;
  Eigen::MatrixXd d;
  residual(*x, &d);
  if (!d.isZero(0)) solve(&d);
  if (!d.allFinite()) {
    rep.status = Status::error(StatusCode::NumericalError, "solve produced non-finite values");
    return rep;
  }
  *x += d;
  rep.first = rep.last = d.size() ? d.cwiseAbs().maxCoeff() : 0.0;
  double prev = rep.first, rate = 1.0;
  for (int step = 0; step < max_steps && prev > 0; ++step) {
    // The error left after a correction is about rate · |correction| (the iteration contracts
    // by a near-constant factor, ~eps·cond² for normal equations, read off the last two
    // corrections; the first solve's correction is the solution itself, rate 1). Below
    // kRefinementTolerance·|x| a further solve cannot change any digit that matters.
    const double scale = x->cwiseAbs().maxCoeff();
    if (step > 0 && rate * prev <= kRefinementTolerance * scale) break;
    residual(*x, &d);
    // An exactly vanishing residual: nothing left to correct (and no solve to pay for).
    if (d.isZero(0)) break;
    solve(&d);
    const double size = d.allFinite() ? d.cwiseAbs().maxCoeff() : HUGE_VAL;
    // Not smaller than the last correction: the residual is at its rounding level (or the
    // factor is too inexact for the iteration to contract); keep x as it is.
    if (!(size < prev)) break;
    *x += d;
    ++rep.steps;
    rep.last = size;
    if (size <= kRefinementTolerance * scale) break;
    if (size > 0.5 * prev) break;  // barely shrinking: the next step would not help
    rate = size / prev;
    prev = size;
  }
  return rep;
}

}  // namespace mm
