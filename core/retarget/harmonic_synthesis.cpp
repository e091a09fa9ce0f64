#include "retarget/harmonic_synthesis.h"

#include <cassert>

#include <Eigen/Cholesky>

namespace mm {

struct HarmonicSynthesis::Impl {
  Eigen::LLT<Eigen::MatrixXd> llt;
};

HarmonicSynthesis::HarmonicSynthesis() : impl_(std::make_unique<Impl>()) {}
HarmonicSynthesis::~HarmonicSynthesis() = default;
HarmonicSynthesis::HarmonicSynthesis(HarmonicSynthesis&&) noexcept = default;
HarmonicSynthesis& HarmonicSynthesis::operator=(HarmonicSynthesis&&) noexcept = default;

int HarmonicSynthesis::add_term(SynthesisTerm term) {
  assert((n_ < 0 || term.A.cols() == n_) && "all synthesis terms must have N_a columns");
  n_ = static_cast<int>(term.A.cols());
  terms_.push_back(std::move(term));
  factored_ = false;
  return num_terms() - 1;
}

int HarmonicSynthesis::find_term(const std::string& name) const {
  for (int k = 0; k < num_terms(); ++k)
    if (terms_[k].name == name) return k;
  return -1;
}

Status HarmonicSynthesis::factor(double ridge) {
  factored_ = false;
  if (n_ <= 0) return Status::error(StatusCode::InvalidArgument, "synthesis has no terms");
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(n_, n_);
  for (const SynthesisTerm& t : terms_) {
    if (t.A.rows() == 0 || t.weight == 0) continue;
    N.selfadjointView<Eigen::Lower>().rankUpdate(t.A.transpose(), t.weight);
  }
  N.triangularView<Eigen::Upper>() = N.transpose();
  if (!N.allFinite()) return Status::error(StatusCode::NumericalError, "synthesis normal matrix is not finite");
  const double mean_diag = N.diagonal().mean();
  if (!(mean_diag > 0)) return Status::error(StatusCode::FactorizationFailed, "synthesis normal matrix is zero");
  N.diagonal().array() += ridge * mean_diag;
  impl_->llt.compute(N);
  if (impl_->llt.info() != Eigen::Success)
    return Status::error(StatusCode::FactorizationFailed,
                         "synthesis normal matrix is not positive definite (raise the ridge)");
  factored_ = true;
  return Status::success();
}

Eigen::MatrixXd HarmonicSynthesis::solution_operator(int k, const Eigen::MatrixXd& M) const {
  assert(factored_ && k >= 0 && k < num_terms());
  const SynthesisTerm& t = terms_[k];
  if (M.size() == 0) return impl_->llt.solve(t.weight * t.A.transpose());
  assert(M.rows() == t.A.rows());
  return impl_->llt.solve(t.weight * (t.A.transpose() * M));
}

std::vector<double> HarmonicSynthesis::energies(const std::vector<const Eigen::MatrixXd*>& B,
                                                const Eigen::MatrixXd& W) const {
  std::vector<double> e;
  for (int k = 0; k < num_terms(); ++k) {
    const SynthesisTerm& t = terms_[k];
    Eigen::MatrixXd R = t.A * W;
    if (!t.zero_rhs && k < static_cast<int>(B.size()) && B[k] && B[k]->size() > 0) R -= *B[k];
    e.push_back(t.weight * R.squaredNorm());
  }
  return e;
}

}  // namespace mm
