#include "spectral/coupled_bases.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/QR>

namespace mm {

namespace coupled_detail {

struct Problem {
  Eigen::VectorXd ls, lr;  // normalized eigenvalues
  Eigen::MatrixXd Cs, Cr;  // k' by p landmark coefficients
  double w = 1;            // μ / p
};

double off_diagonal(const Eigen::MatrixXd& M) { return M.squaredNorm() - M.diagonal().squaredNorm(); }

double energy(const Problem& P, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y) {
  const Eigen::MatrixXd Ms = X.transpose() * P.ls.asDiagonal() * X;
  const Eigen::MatrixXd Mr = Y.transpose() * P.lr.asDiagonal() * Y;
  const Eigen::MatrixXd D = P.Cs.transpose() * X - P.Cr.transpose() * Y;
  return off_diagonal(Ms) + off_diagonal(Mr) + P.w * D.squaredNorm();
}

// Euclidean gradients of the energy.
void gradient(const Problem& P, const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, Eigen::MatrixXd* GX,
              Eigen::MatrixXd* GY) {
  Eigen::MatrixXd Ms = X.transpose() * P.ls.asDiagonal() * X;
  Eigen::MatrixXd Mr = Y.transpose() * P.lr.asDiagonal() * Y;
  Ms.diagonal().setZero();
  Mr.diagonal().setZero();
  const Eigen::MatrixXd D = P.Cs.transpose() * X - P.Cr.transpose() * Y;
  *GX = 4.0 * P.ls.asDiagonal() * X * Ms + 2.0 * P.w * P.Cs * D;
  *GY = 4.0 * P.lr.asDiagonal() * Y * Mr - 2.0 * P.w * P.Cr * D;
}

// Tangent projection on the Stiefel manifold (embedded metric).
Eigen::MatrixXd stiefel_project(const Eigen::MatrixXd& X, const Eigen::MatrixXd& G) {
  const Eigen::MatrixXd XtG = X.transpose() * G;
  return G - X * (0.5 * (XtG + XtG.transpose()));
}

// QR retraction with positive diag(R): deterministic and smooth.
Eigen::MatrixXd stiefel_retract(const Eigen::MatrixXd& M) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(M);
  Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(M.rows(), M.cols());
  const Eigen::MatrixXd R = qr.matrixQR().topRows(M.cols()).triangularView<Eigen::Upper>();
  for (int c = 0; c < M.cols(); ++c)
    if (R(c, c) < 0) Q.col(c) = -Q.col(c);
  return Q;
}

}  // namespace coupled_detail

void functional_matrix(const Eigen::MatrixXd& coeff_source, const Eigen::MatrixXd& coeff_reference, int rows,
                       Eigen::MatrixXd* gamma, double* dominance) {
  const int k = static_cast<int>(coeff_source.rows());
  Eigen::MatrixXd S = coeff_source * coeff_source.transpose();
  // A tiny ridge keeps Γ defined when there are fewer landmarks than basis functions.
  S.diagonal().array() += 1e-12 * std::max(1e-300, S.trace() / std::max(1, k));
  *gamma = S.ldlt().solve(coeff_source * coeff_reference.transpose()).transpose();
  double dom = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::min(rows, k); ++i) {
    double off = 0;
    for (int j = 0; j < k; ++j)
      if (j != i) off += std::abs((*gamma)(i, j));
    dom = std::min(dom, std::abs((*gamma)(i, i)) / std::max(off, 1e-300));
  }
  *dominance = dom;
}

CoupledBases coupled_bases(const Eigen::MatrixXd& Phi_source, const Eigen::VectorXd& lambda_source,
                           const Eigen::VectorXd& mass_source, const Eigen::MatrixXd& F_source,
                           const Eigen::MatrixXd& Phi_reference, const Eigen::VectorXd& lambda_reference,
                           const Eigen::VectorXd& mass_reference, const Eigen::MatrixXd& F_reference,
                           const CoupledBasesOptions& opt, const Progress& progress) {
  using namespace coupled_detail;
  CoupledBases out;
  const int kp = static_cast<int>(Phi_source.cols());
  const int k = opt.num_coupled;
  const int p = static_cast<int>(F_source.cols());
  if (Phi_reference.cols() != kp || lambda_source.size() != kp || lambda_reference.size() != kp ||
      F_reference.cols() != p || Phi_source.rows() != mass_source.size() || F_source.rows() != Phi_source.rows() ||
      Phi_reference.rows() != mass_reference.size() || F_reference.rows() != Phi_reference.rows()) {
    out.status = Status::error(StatusCode::InvalidArgument, "coupled bases: inconsistent matrix sizes");
    return out;
  }
  if (k < 1 || k > kp || p < 1) {
    out.status = Status::error(StatusCode::InvalidArgument,
                               "coupled bases: need 1 <= k (" + std::to_string(k) + ") <= k' (" + std::to_string(kp) +
                                   ") and at least one landmark function");
    return out;
  }
  Problem P;
  const double lmax = std::max({lambda_source.maxCoeff(), lambda_reference.maxCoeff(), 1e-300});
  P.ls = lambda_source / lmax;
  P.lr = lambda_reference / lmax;
  P.Cs = Phi_source.transpose() * mass_source.asDiagonal() * F_source;
  P.Cr = Phi_reference.transpose() * mass_reference.asDiagonal() * F_reference;
  P.w = opt.mu / p;

  // Initial signed matching of reference eigenvectors to source eigenvectors.
  struct Cand {
    double c;
    int i, j;
  };
  std::vector<Cand> cands;
  for (int i = 0; i < kp; ++i)
    for (int j = std::max(0, i - opt.match_window); j <= std::min(kp - 1, i + opt.match_window); ++j) {
      const double den = P.Cs.row(i).norm() * P.Cr.row(j).norm();
      cands.push_back({den > 0 ? P.Cs.row(i).dot(P.Cr.row(j)) / den : 0.0, i, j});
    }
  std::stable_sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) {
    if (std::abs(a.c) != std::abs(b.c)) return std::abs(a.c) > std::abs(b.c);
    return a.i != b.i ? a.i < b.i : a.j < b.j;
  });
  std::vector<int> match(kp, -1), used(kp, 0);
  std::vector<double> sign(kp, 1.0);
  for (const Cand& c : cands)
    if (match[c.i] < 0 && !used[c.j]) {
      match[c.i] = c.j;
      used[c.j] = 1;
      sign[c.i] = c.c < 0 ? -1.0 : 1.0;
    }
  for (int i = 0; i < kp; ++i)
    if (match[i] < 0)
      for (int j = 0; j < kp; ++j)
        if (!used[j]) {
          match[i] = j;
          used[j] = 1;
          break;
        }
  Eigen::MatrixXd X = Eigen::MatrixXd::Identity(kp, k);
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(kp, k);
  for (int c = 0; c < k; ++c) Y(match[c], c) = sign[c];

  // Riemannian gradient descent with Armijo backtracking.
  double E = energy(P, X, Y);
  out.energy_initial = E;
  Eigen::MatrixXd GX, GY;
  gradient(P, X, Y, &GX, &GY);
  Eigen::MatrixXd RX = stiefel_project(X, GX), RY = stiefel_project(Y, GY);
  const double g0 = std::sqrt(RX.squaredNorm() + RY.squaredNorm());
  double step = 1.0;
  std::vector<double> history{E};
  int it = 0;
  for (; it < opt.max_iterations; ++it) {
    const double g2 = RX.squaredNorm() + RY.squaredNorm();
    if (std::sqrt(g2) <= opt.tolerance * std::max(g0, 1e-300)) {
      out.converged = true;
      break;
    }
    if (history.size() > 10 && history[history.size() - 11] - E <= opt.tolerance * std::abs(E)) {
      out.converged = true;
      break;
    }
    if ((it & 63) == 0 && !progress.update("coupled bases", double(it) / opt.max_iterations)) {
      out.status = cancelled_status("coupled bases");
      return out;
    }
    bool accepted = false;
    for (int tries = 0; tries < 40; ++tries) {
      const Eigen::MatrixXd Xn = stiefel_retract(X - step * RX), Yn = stiefel_retract(Y - step * RY);
      const double En = energy(P, Xn, Yn);
      if (En <= E - 1e-4 * step * g2) {
        X = Xn;
        Y = Yn;
        E = En;
        accepted = true;
        step *= 2.0;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) {  // no descent possible at machine precision: a stationary point
      out.converged = true;
      break;
    }
    history.push_back(E);
    gradient(P, X, Y, &GX, &GY);
    RX = stiefel_project(X, GX);
    RY = stiefel_project(Y, GY);
  }
  out.iterations = it;
  out.energy_final = E;

  // Sort the coupled pairs by their mean normalized Rayleigh quotient.
  const Eigen::VectorXd qs = (X.transpose() * P.ls.asDiagonal() * X).diagonal();
  const Eigen::VectorXd qr = (Y.transpose() * P.lr.asDiagonal() * Y).diagonal();
  std::vector<int> order(k);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return qs[a] + qr[a] < qs[b] + qr[b]; });
  Eigen::MatrixXd Xs(kp, k), Ys(kp, k);
  for (int c = 0; c < k; ++c) {
    Xs.col(c) = X.col(order[c]);
    Ys.col(c) = Y.col(order[c]);
  }
  out.X = Xs;
  out.Y = Ys;
  out.source = Phi_source * Xs;
  out.reference = Phi_reference * Ys;
  functional_matrix(Xs.transpose() * P.Cs, Ys.transpose() * P.Cr, opt.dominance_rows, &out.gamma,
                    &out.diagonal_dominance);
  if (!out.source.allFinite() || !out.reference.allFinite() || !out.gamma.allFinite()) {
    out.status = Status::error(StatusCode::NumericalError, "coupled bases are not finite");
    return out;
  }
  progress.update("coupled bases", 1.0);
  return out;
}

}  // namespace mm
