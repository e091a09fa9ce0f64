// SpdSolver: a prefactored sparse symmetric positive (semi-)definite solve — factor once,
// then solve many right-hand sides (handle drags, animation frames, eigensolver steps).
//
// Wraps Eigen::SimplicialLDLT with AMD ordering (the fastest plain-Eigen option natively and
// in wasm; CHOLMOD is not available in wasm). Factorization failure (matrix not SPD, or
// numerically singular) is reported as StatusCode::FactorizationFailed, never a crash.
#pragma once

#include <memory>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/status.h"

namespace mm {

class SpdSolver {
 public:
  SpdSolver();
  ~SpdSolver();
  SpdSolver(SpdSolver&&) noexcept;
  SpdSolver& operator=(SpdSolver&&) noexcept;

  // Analyses the pattern and factors A (n by n, symmetric; only the lower triangle is read).
  Status factor(const Eigen::SparseMatrix<double>& A);

  // Refactors a matrix with the same sparsity pattern as the last factor() (skips analysis).
  Status refactor(const Eigen::SparseMatrix<double>& A);

  bool factored() const { return factored_; }
  int size() const { return n_; }

  // X = A⁻¹B for B n by k. Returns NumericalError if the result is not finite.
  Status solve(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const;

  // Unchecked in-place variant for hot loops (caller guarantees factored() and sizes).
  void solve_in_place(Eigen::Ref<Eigen::MatrixXd> B) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool factored_ = false;
  int n_ = 0;
};

}  // namespace mm
