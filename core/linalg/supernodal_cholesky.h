// SupernodalCholesky: sparse LLᵀ for the dense-ish normal equations of implicit Laplacian editing
// (paper 001 Eq. 7: AᵀA couples vertices up to 4 rings apart, ~60 nonzeros per row, and its
// Cholesky factor has ~250 nonzeros per column at 50k vertices).
//
// Multifrontal with supernodes: AMD ordering (Eigen's) + postorder of the elimination tree,
// fundamental supernodes with relaxed amalgamation, and dense Eigen kernels (LLT, triangular
// solve, rank-k update) on each frontal matrix. Against Eigen::SimplicialLDLT (column by column,
// no dense kernels) this measured 2.5× (52k vertices) to 3.7× (14.6k) faster on these matrices,
// and it solves several right-hand sides at once with matrix-matrix products. Used by core/edit; experimental elsewhere (only tested on SPD systems
// of this kind); linalg/spd_solver.h stays the general-purpose solver.
//
// Status: FactorizationFailed when a pivot is not positive (matrix not SPD or numerically
// singular); Cancelled when the progress sink asks to stop (checked between supernodes).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/progress.h"
#include "common/status.h"

namespace mm {

class SupernodalCholesky {
 public:
  // A: n by n symmetric positive definite; only the lower triangle is read. (AMD must run on
  // A's own pattern: orderings computed on a sparser graph of the same mesh — 1- or 2-ring —
  // gave 5× the fill on these matrices.)
  Status factor(const Eigen::SparseMatrix<double>& A, const Progress& progress = {});

  // Natively, with max_threads() > 1, factorizations of at least this many flops (Σ ncols·m² over
  // the supernodes) share the elimination tree's lower subtrees between two threads; the factor is
  // bit-identical either way.
  double parallel_min_flops = 5e8;

  bool factored() const { return factored_; }
  int size() const { return n_; }
  long factor_entries() const { return values_size_; }  // stored (dense) entries of L
  int supernodes() const { return static_cast<int>(start_.size()) - 1; }

  // X = A⁻¹ B for B n by k. NumericalError if the result is not finite. A factor computed on two
  // threads also solves on two (the subtrees below its cut; same bits as on one).
  Status solve(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const;
  // In place, unchecked (caller guarantees factored() and B.rows() == size()).
  void solve_in_place(Eigen::MatrixXd& B) const;

 private:
  int n_ = 0;
  bool factored_ = false;
  std::vector<int> perm_;          // perm_[i] = position of original row i in the factor
  std::vector<int> start_;         // supernode s owns factor columns [start_[s], start_[s+1])
  std::vector<int> rows_ptr_;      // rows below the diagonal block of s: rows_[rows_ptr_[s] .. rows_ptr_[s+1])
  std::vector<int> rows_;
  std::vector<long> value_ptr_;    // dense block of s: (ncols + nrows) by ncols, column-major
  // Not zero-filled when allocated (the factorization writes every entry: 111 MB at 50k vertices,
  // whose zeroing the kernel does anyway on first touch).
  std::unique_ptr<double[]> values_;
  long values_size_ = 0;
  // The factor's two-thread split, kept for the solves (empty when it factored on one thread):
  // supernodes above the cut, and per thread the subtrees (root s covers supernodes first_[s]..s).
  std::vector<char> top_;
  std::vector<int> first_;
  std::vector<int> bins_[2];
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  struct SolveLog {  // updates a subtree's forward solve aimed above the cut, in order
    std::vector<int> rows;
    std::vector<double> values;
  };
  void solve_split(RowMatrix& Y) const;
  // One supernode of the forward (L y = b) and backward (Lᵀ x = y) solves on the permuted rows Y.
  // Forward: updates of rows ≥ limit go to `log` instead of Y when a log is given.
  void forward_supernode(int s, RowMatrix& Y, RowMatrix& tmp, int limit, SolveLog* log) const;
  void backward_supernode(int s, RowMatrix& Y, RowMatrix& tmp) const;
};

// The symbolic steps, exposed for tests (tests/linalg_test.cpp).
namespace supernodal_detail {
// Lower (or upper) triangle of P A Pᵀ from A's lower triangle; row i of A becomes p[i].
Eigen::SparseMatrix<double> sn_permuted_triangle(const Eigen::SparseMatrix<double>& A, const std::vector<int>& p, bool upper);
// Elimination tree from the upper triangle (parent −1 at roots).
std::vector<int> sn_elimination_tree(const Eigen::SparseMatrix<double>& U);
// order[k] = the node visited k-th by a postorder of the forest.
std::vector<int> sn_postorder(const std::vector<int>& parent);
// Off-diagonal column counts of L from the lower triangle C of a matrix numbered in a postorder of
// its elimination tree `parent`.
std::vector<int> sn_column_counts(const Eigen::SparseMatrix<double>& C, const std::vector<int>& parent);
}  // namespace supernodal_detail

}  // namespace mm
