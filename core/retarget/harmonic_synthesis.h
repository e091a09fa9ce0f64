// Least-squares synthesis of the target's MFS coefficients Wt (paper 002 Sec. 5, 7.2,
// Eq. 15–18) from a list of terms E_k = w_k ‖A_k Wt − B_k‖²_F.
//
// Every term's matrix A_k is fixed per character pair, so the normal matrix
// N = Σ w_k A_kᵀA_k (+ a tiny ridge) is factored once (dense Cholesky, N_a by N_a). The solution
// Wt = N⁻¹ Σ w_k A_kᵀ B_k (Eq. 18) is linear in each right-hand side, so the caller forms the
// operators N⁻¹ w_k A_kᵀ M_k once (solution_operator) and each frame is a few small products.
// The three columns of Wt (x, y, z) share N.
//
// Terms are open-ended so that the context-graph terms (spatial, volume; paper Sec. 6) plug in
// beside affine, position, bone and smoothness: add the term, refactor, take its operator.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace mm {

struct SynthesisTerm {
  std::string name;        // "affine", "position", "bone", "smooth", "spatial", "volume", ...
  Eigen::MatrixXd A;       // rows by N_a coefficient block of Eq. 17
  double weight = 1;       // w_k: λ of Eq. 15 divided by the term's normalisation (see the caller)
  bool zero_rhs = false;   // B_k is always 0 (smoothness, volume of the rest shape): skipped per frame
};

class HarmonicSynthesis {
 public:
  HarmonicSynthesis();
  ~HarmonicSynthesis();
  HarmonicSynthesis(HarmonicSynthesis&&) noexcept;
  HarmonicSynthesis& operator=(HarmonicSynthesis&&) noexcept;

  // Adds a term (A must have N_a columns, the same for all terms) and returns its index.
  // Invalidates the factorization.
  int add_term(SynthesisTerm term);
  int find_term(const std::string& name) const;  // -1 when absent
  const SynthesisTerm& term(int k) const { return terms_[k]; }
  int num_terms() const { return static_cast<int>(terms_.size()); }
  int num_unknowns() const { return n_; }

  // Forms and factors N. `ridge` × mean(diag N) is added to the diagonal: the MFS basis is
  // nearly dependent (As is ill-conditioned, Sec. 7.1), so directions no term sees would
  // otherwise make N singular. FactorizationFailed when N is still not positive definite.
  Status factor(double ridge = 1e-9);
  bool factored() const { return factored_; }

  // The solution is linear in each right-hand side: Wt = Σ_k N⁻¹ w_k A_kᵀ B_k. When B_k = M_k y
  // for a fixed M_k (rows_k by c) and a per-frame y, the operator N⁻¹ w_k A_kᵀ M_k (N_a by c)
  // can be formed once and each frame costs one small product (HarmonicRetargeter does this).
  // M = empty means the identity (returns N⁻¹ w_k A_kᵀ).
  Eigen::MatrixXd solution_operator(int k, const Eigen::MatrixXd& M = Eigen::MatrixXd()) const;

  // Value of Σ w_k ‖A_k W − B_k‖² per term (diagnostics and tests).
  std::vector<double> energies(const std::vector<const Eigen::MatrixXd*>& B, const Eigen::MatrixXd& W) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<SynthesisTerm> terms_;
  int n_ = -1;
  bool factored_ = false;
};

}  // namespace mm
