#include "spectral/spectral_basis.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include "common/threads.h"
#include "linalg/block_lanczos.h"
#include "linalg/supernodal_cholesky.h"
#include "operators/operators.h"

namespace mm {

namespace {

struct CancelRequested {};

// y = (W - σA)⁻¹ x through SimplicialLDLT: ~1.9× faster than Spectra's stock SparseLU
// operator, natively and in wasm (TOOLCHAIN.md §4, PEERS.md).
class ShiftInvertLdlt {
 public:
  using Scalar = double;
  ShiftInvertLdlt(const Eigen::SparseMatrix<double>& W, const Eigen::SparseMatrix<double>& A,
                  const Progress& progress, int expected_ops)
      : W_(W), A_(A), progress_(progress), expected_ops_(std::max(1, expected_ops)) {}

  Eigen::Index rows() const { return W_.rows(); }
  Eigen::Index cols() const { return W_.cols(); }

  void set_shift(double sigma) {
    if (factored_ && sigma == sigma_) return;  // a second guard pass reuses the factor
    sigma_ = sigma;
    factored_ = false;
    Eigen::SparseMatrix<double> M = W_ - sigma * A_;
    ldlt_.compute(M);
    if (ldlt_.info() != Eigen::Success) throw std::runtime_error("factorization of W - sigma A failed");
    factored_ = true;
  }

  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, W_.rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, W_.rows());
    y.noalias() = ldlt_.solve(x);
    ++ops_;
    // Spectra has no progress hook; the operator is called once per Lanczos step.
    const double f = 1.0 - std::exp(-static_cast<double>(ops_) / expected_ops_);
    if (!progress_.update("eigenbasis", f)) throw CancelRequested{};
  }

  int ops() const { return ops_; }

 private:
  const Eigen::SparseMatrix<double>& W_;
  const Eigen::SparseMatrix<double>& A_;
  Progress progress_;
  int expected_ops_;
  mutable int ops_ = 0;
  double sigma_ = 0;
  bool factored_ = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
};

// The number of eigenvalues of W φ = λ A φ below tau: the negative pivots of LDLᵀ(W - τA)
// (Sylvester's law of inertia); the symbolic analysis is shared by every call. -1 if the
// factorization breaks down (an exact zero pivot).
class InertiaCount {
 public:
  InertiaCount(const Eigen::SparseMatrix<double>& W, const Eigen::SparseMatrix<double>& A) : W_(W), A_(A) {}
  int below(double tau) {
    Eigen::SparseMatrix<double> M = W_ - tau * A_;
    if (!analyzed_) {
      ldlt_.analyzePattern(M);
      analyzed_ = true;
    }
    ldlt_.factorize(M);
    if (ldlt_.info() != Eigen::Success) return -1;
    const Eigen::VectorXd d = ldlt_.vectorD();
    if (!d.allFinite()) return -1;
    return static_cast<int>((d.array() < 0).count());
  }

 private:
  const Eigen::SparseMatrix<double>& W_;
  const Eigen::SparseMatrix<double>& A_;
  bool analyzed_ = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
};

// One Lanczos run for nev pairs of W φ = λ A φ near σ, unsorted.
struct LanczosRun {
  Status status;
  Eigen::VectorXd values;
  Eigen::MatrixXd vectors;  // A-orthonormal
  int iterations = 0;
};

LanczosRun run_spectra(ShiftInvertLdlt& op, const Eigen::SparseMatrix<double>& A, int n, int nev, double sigma,
                       const SpectralBasisOptions& opt) {
  LanczosRun run;
  const int ncv = opt.ncv > 0 ? std::min(n, std::max(opt.ncv, nev + 1)) : std::min(n, std::max(2 * nev + 1, nev + 20));
  Spectra::SparseSymMatProd<double> bop(A);
  try {
    Spectra::SymGEigsShiftSolver<ShiftInvertLdlt, Spectra::SparseSymMatProd<double>, Spectra::GEigsMode::ShiftInvert>
        solver(op, bop, nev, ncv, sigma);
    solver.init();
    solver.compute(Spectra::SortRule::LargestMagn, opt.max_iterations, opt.tolerance, Spectra::SortRule::SmallestAlge);
    run.iterations = static_cast<int>(solver.num_iterations());
    if (solver.info() != Spectra::CompInfo::Successful) {
      run.status = Status::error(StatusCode::NotConverged, "eigensolver did not converge in " +
                                                               std::to_string(opt.max_iterations) +
                                                               " restarts (k = " + std::to_string(opt.k) + ")");
      return run;
    }
    run.values = solver.eigenvalues();
    run.vectors = solver.eigenvectors();
  } catch (const CancelRequested&) {
    run.status = cancelled_status("eigenbasis");
  } catch (const std::exception& e) {
    run.status = Status::error(StatusCode::FactorizationFailed, std::string("eigensolver: ") + e.what());
  }
  return run;
}

// Shift-invert in symmetric form: with D = A^½ and y = D φ, the pairs are the largest θ of
// D (W - σA)⁻¹ D y = θ y, λ = σ + 1/θ (W - σA is SPD for σ < 0: one supernodal Cholesky).
// expected: the operator applications the progress fraction 1 − exp(−applications / expected)
// is scaled to, the same for every pass (applications accumulate over the passes, so a later
// pass's larger nev must not lower it: the bar went back at each second pass).
LanczosRun run_block(const SupernodalCholesky& chol, const Eigen::VectorXd& d, int nev, int block,
                     const SpectralBasisOptions& opt, const Progress& progress, double sigma, double expected,
                     int* applications) {
  LanczosRun run;
  const int n = static_cast<int>(d.size());
  BlockLanczosOptions bo;
  bo.nev = nev;
  bo.block = block;
  bo.max_dim = opt.ncv;
  bo.tolerance = opt.tolerance;
  bo.max_restarts = opt.max_iterations;
  const BlockLanczosResult r = block_lanczos(
      n,
      [&](const Eigen::MatrixXd& X, Eigen::MatrixXd* Y) {
        // The block's two column halves are solved apart (as tasks: two threads when there are),
        // always split the same way so the bits do not depend on the thread count.
        const Eigen::Index h = X.cols() / 2;
        Eigen::MatrixXd Y2 = d.asDiagonal() * X.rightCols(X.cols() - h);
        Task second([&] { chol.solve_in_place(Y2); });
        Eigen::MatrixXd Y1 = d.asDiagonal() * X.leftCols(h);
        chol.solve_in_place(Y1);
        second.wait();
        Y->resize(X.rows(), X.cols());
        Y->leftCols(h) = d.asDiagonal() * Y1;
        Y->rightCols(X.cols() - h) = d.asDiagonal() * Y2;
        *applications += static_cast<int>(X.cols());
        return progress.update("eigenbasis", 1.0 - std::exp(-*applications / expected));
      },
      bo);
  run.status = r.status;
  run.iterations = r.restarts;
  if (!r.status.ok()) return run;
  run.values = (sigma + r.values.array().inverse()).matrix();
  run.vectors = d.cwiseInverse().asDiagonal() * r.vectors;
  return run;
}

// Small meshes: every pair at once (D⁻¹ W D⁻¹ is n by n), complete by construction.
LanczosRun run_dense(const Eigen::SparseMatrix<double>& W, const Eigen::VectorXd& d) {
  LanczosRun run;
  const Eigen::MatrixXd Wd = d.cwiseInverse().asDiagonal() * Eigen::MatrixXd(W) * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Wd);
  if (es.info() != Eigen::Success) {
    run.status = Status::error(StatusCode::NotConverged, "dense eigensolver did not converge");
    return run;
  }
  run.values = es.eigenvalues();
  run.vectors = d.cwiseInverse().asDiagonal() * es.eigenvectors();
  return run;
}

}  // namespace

bool parse_eigen_solver(const std::string& name, EigenSolverKind* kind) {
  if (name == "auto") *kind = EigenSolverKind::Auto;
  else if (name == "block") *kind = EigenSolverKind::BlockLanczos;
  else if (name == "spectra") *kind = EigenSolverKind::Spectra;
  else return false;
  return true;
}

SpectralBasis spectral_basis(const Eigen::SparseMatrix<double>& W, const Eigen::VectorXd& mass,
                             const SpectralBasisOptions& opt, const Progress& progress) {
  SpectralBasis out;
  const int n = static_cast<int>(W.rows());
  if (opt.k < 1 || opt.k >= n) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "asked for " + std::to_string(opt.k) + " eigenpairs of a mesh with " +
                                   std::to_string(n) + " vertices (need 1 <= k < #V)");
    return out;
  }
  for (int i = 0; i < n; ++i)
    if (!(mass[i] > 0) || !std::isfinite(mass[i])) {
      out.status = Status::error(StatusCode::InvalidMesh,
                                 "vertex " + std::to_string(i) +
                                     " has zero or invalid area (unreferenced vertex or degenerate faces); "
                                     "clean the mesh first");
      return out;
    }
  Eigen::SparseMatrix<double> A(n, n);
  {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i) t.emplace_back(i, i, mass[i]);
    A.setFromTriplets(t.begin(), t.end());
  }
  const double sigma = -opt.relative_shift * W.diagonal().sum() / mass.sum();

  // Completeness by inertia instead of guard pairs. Lanczos can miss copies of a multiple
  // eigenvalue, at the edge of the range and inside it (the icosphere's 5-fold λ ≈ 6 came back as
  // 3 copies with nev = k = 11). Asking for k + max(5, k/10) pairs every time hid this on the
  // cases seen, at 13–30 % of the solve (PEERS.md), and proved nothing. Now each pass asks for
  // the pairs needed, then counts the eigenvalues below τ (just above λ_{k-1}) exactly: by
  // Sylvester's law of inertia, the negative pivots of LDLᵀ(W - τA). If the count exceeds the
  // computed values below τ, some were missed: the next pass asks for more.
  const Eigen::VectorXd d = mass.cwiseSqrt();
  const double basis_mib = static_cast<double>(n) * (2.0 * opt.k + 1) * 8.0 / (1 << 20);
  const bool spectra = opt.solver == EigenSolverKind::Spectra ||
                       (opt.solver == EigenSolverKind::Auto && basis_mib < opt.block_min_basis_mib);
  // The block solver needs n ≥ its Krylov space plus a block; smaller meshes are solved densely.
  const int block_min_n = 4 * std::max(opt.k + 24, 2 * opt.k + 24);
  if (n <= opt.dense_max_vertices || (!spectra && n < block_min_n)) {
    LanczosRun run = run_dense(W, d);
    if (!run.status.ok()) {
      out.status = run.status;
      return out;
    }
    out.eigenvalues = run.values;
    out.vectors = run.vectors;
    out.passes = 1;
    out.solver = "dense";
  } else {
    // Operator applications the progress fraction is scaled to, by k (not by a pass's nev), for
    // both solvers.
    const int expected_ops = 3 * std::min(n, std::max(2 * opt.k + 1, opt.k + 20));
    ShiftInvertLdlt op(W, A, progress, expected_ops);
    SupernodalCholesky chol;
    if (!spectra) {
      const Eigen::SparseMatrix<double> M = W - sigma * A;
      const Status fs = chol.factor(M, progress.sub(0.0, 0.05, "eigenbasis"));

      if (!fs.ok()) {
        out.status = fs.code == StatusCode::Cancelled
                         ? cancelled_status("eigenbasis")
                         : Status::error(StatusCode::FactorizationFailed, "eigensolver: factorization of W - sigma A failed (" + fs.message + ")");
        return out;
      }
    }
    InertiaCount inertia(W, A);
    out.solver = spectra ? "Spectra" : "block Lanczos";
    const double tau_floor = std::abs(sigma);  // the scale at which λ₀ = 0 is told apart
    int nev = opt.k, applications = 0;
    // Block Lanczos finds at most b copies of an exactly repeated eigenvalue (a Krylov space
    // meets each eigenspace in at most b dimensions; rounding supplies more copies only slowly —
    // in wasm the icosphere's 5-fold λ ≈ 20 came back short after 4 passes with b = 4), so a
    // pass after missed eigenvalues doubles the block.
    int block = opt.block > 0 ? opt.block : std::clamp(nev / 12, 4, 8);
    Eigen::VectorXd sorted;
    for (int pass = 0;; ++pass) {
      LanczosRun run = spectra ? run_spectra(op, A, n, nev, sigma, opt)
                               : run_block(chol, d, nev, block, opt, progress.sub(0.05, 1.0), sigma,
                                           expected_ops, &applications);
      out.iterations += run.iterations;
      if (!run.status.ok()) {
        out.status = run.status;
        return out;
      }
      out.eigenvalues = run.values;
      out.vectors = run.vectors;
      out.passes = pass + 1;
      out.operations = spectra ? op.ops() : applications;
      sorted = out.eigenvalues;
      std::sort(sorted.data(), sorted.data() + sorted.size());
      const double lam = sorted[opt.k - 1];
      double tau = lam + std::max(opt.cluster_gap * std::abs(lam), tau_floor);
      if (opt.k < sorted.size()) tau = std::min(tau, 0.5 * (lam + sorted[opt.k]));
      const int computed = static_cast<int>(std::lower_bound(sorted.data(), sorted.data() + sorted.size(), tau) - sorted.data());
      const int below = inertia.below(tau);

      if (below < 0 || below <= computed) break;  // complete (or the count failed: keep the old guarantee)
      if (pass >= 3 || nev >= n - 1) {
        out.status = Status::error(StatusCode::NotConverged,
                                   "eigensolver: " + std::to_string(below) + " eigenvalues lie below " +
                                       std::to_string(tau) + " but Lanczos found " + std::to_string(computed) +
                                       " after " + std::to_string(pass + 1) + " passes (k = " + std::to_string(opt.k) + ")");
        return out;
      }
      out.missed += below - computed;
      nev = std::min(n - 1, std::max(nev, below) + std::max(5, opt.k / 10));
      block = std::min(2 * block, 32);
    }
  }

  // Ascending order (stable, so ties keep Spectra's deterministic order).
  std::vector<int> order(out.eigenvalues.size());  // nev entries; the first k are kept
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return out.eigenvalues[a] < out.eigenvalues[b]; });
  order.resize(std::min<size_t>(order.size(), opt.k));
  Eigen::VectorXd lambda(order.size());
  Eigen::MatrixXd phi(n, order.size());
  Eigen::VectorXd weight(n);
  for (int i = 0; i < n; ++i) weight[i] = mass[i] * (1.0 + static_cast<double>(i) / n);
  for (size_t c = 0; c < order.size(); ++c) {
    lambda[c] = out.eigenvalues[order[c]];
    phi.col(c) = out.vectors.col(order[c]);
    if (phi.col(c).dot(weight) < 0) phi.col(c) = -phi.col(c);
  }
  out.eigenvalues = lambda;
  out.vectors = phi;
  if (!out.vectors.allFinite() || !out.eigenvalues.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "eigensolver produced non-finite values");
    return out;
  }
  progress.update("eigenbasis", 1.0);
  return out;
}

SpectralBasis spectral_basis(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                             const SpectralBasisOptions& opt, const Progress& progress) {
  return spectral_basis(cotan_stiffness(V, F), mass_diagonal(V, F), opt, progress);
}

}  // namespace mm
