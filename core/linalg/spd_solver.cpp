#include "linalg/spd_solver.h"

#include <Eigen/SparseCholesky>

namespace mm {

struct SpdSolver::Impl {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
};

SpdSolver::SpdSolver() : impl_(std::make_unique<Impl>()) {}
SpdSolver::~SpdSolver() = default;
SpdSolver::SpdSolver(SpdSolver&&) noexcept = default;
SpdSolver& SpdSolver::operator=(SpdSolver&&) noexcept = default;

namespace {

// LDLT "succeeds" on indefinite or singular matrices; check the pivots ourselves.
Status check_pivots(const Eigen::VectorXd& D) {
  if (D.size() == 0) return Status::success();
  const double max_abs = D.cwiseAbs().maxCoeff();
  for (int i = 0; i < D.size(); ++i) {
    if (!std::isfinite(D[i]) || D[i] <= 1e-14 * max_abs)
      return Status::error(StatusCode::FactorizationFailed,
                           "system matrix is singular or not positive definite (pivot " +
                               std::to_string(i) + " = " + std::to_string(D[i]) + ")");
  }
  return Status::success();
}

}  // namespace

Status SpdSolver::factor(const Eigen::SparseMatrix<double>& A) {
  factored_ = false;
  if (A.rows() != A.cols())
    return Status::error(StatusCode::InvalidArgument, "system matrix must be square");
  n_ = static_cast<int>(A.rows());
  impl_->ldlt.compute(A);
  if (impl_->ldlt.info() != Eigen::Success)
    return Status::error(StatusCode::FactorizationFailed, "sparse LDLT factorization failed");
  Status s = check_pivots(impl_->ldlt.vectorD());
  factored_ = s.ok();
  return s;
}

Status SpdSolver::refactor(const Eigen::SparseMatrix<double>& A) {
  if (A.rows() != n_ || A.cols() != n_) return factor(A);
  factored_ = false;
  impl_->ldlt.factorize(A);
  if (impl_->ldlt.info() != Eigen::Success)
    return Status::error(StatusCode::FactorizationFailed, "sparse LDLT factorization failed");
  Status s = check_pivots(impl_->ldlt.vectorD());
  factored_ = s.ok();
  return s;
}

Status SpdSolver::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const {
  if (!factored_) return Status::error(StatusCode::InvalidArgument, "solve called before a successful factor");
  if (B.rows() != n_) return Status::error(StatusCode::InvalidArgument, "right-hand side has the wrong size");
  *X = impl_->ldlt.solve(B);
  if (!X->allFinite()) return Status::error(StatusCode::NumericalError, "solve produced non-finite values");
  return Status::success();
}

void SpdSolver::solve_in_place(Eigen::Ref<Eigen::MatrixXd> B) const {
  B = impl_->ldlt.solve(B).eval();
}

}  // namespace mm
