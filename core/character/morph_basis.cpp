#include "character/morph_basis.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

namespace mm {

namespace morph_basis_detail {

// Centered displacements of vertices [v0, v0 + c) as an F × 3c block: B(f, 3i + j) =
// frames[f](v0 + i, j) − V_rest(v0 + i, j) − mean(v0 + i, j).
void displacement_block(const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXd& V_rest,
                        const Eigen::MatrixXd& mean, Eigen::Index v0, Eigen::Index c, Eigen::MatrixXd* B) {
  const Eigen::Index F = static_cast<Eigen::Index>(frames.size());
  B->resize(F, 3 * c);
  for (Eigen::Index i = 0; i < c; ++i)
    for (int j = 0; j < 3; ++j) {
      const double offset = V_rest(v0 + i, j) + mean(v0 + i, j);
      double* out = B->col(3 * i + j).data();
      for (Eigen::Index f = 0; f < F; ++f) out[f] = frames[static_cast<size_t>(f)](v0 + i, j) - offset;
    }
}

// Largest squared vertex norm of an F × 3c residual block.
double max_vertex_norm2(const Eigen::MatrixXd& R) {
  double best = 0;
  const Eigen::Index F = R.rows();
  for (Eigen::Index i = 0; i < R.cols() / 3; ++i) {
    const double *x = R.col(3 * i).data(), *y = R.col(3 * i + 1).data(), *z = R.col(3 * i + 2).data();
    for (Eigen::Index f = 0; f < F; ++f) best = std::max(best, x[f] * x[f] + y[f] * y[f] + z[f] * z[f]);
  }
  return best;
}

Status check_frames(const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXd& V_rest) {
  if (frames.empty()) return Status::error(StatusCode::InvalidArgument, "morph basis: no frames");
  for (size_t f = 0; f < frames.size(); ++f)
    if (frames[f].rows() != V_rest.rows() || frames[f].cols() != 3 || !frames[f].allFinite())
      return Status::error(StatusCode::InvalidArgument, "morph basis: frame " + std::to_string(f) + " does not have " +
                                                            std::to_string(V_rest.rows()) + " finite positions");
  return Status::success();
}

}  // namespace morph_basis_detail

MorphBasis morph_basis(const std::vector<Eigen::MatrixXd>& frames, const Eigen::MatrixXd& V_rest,
                       const MorphBasisOptions& opt) {
  using namespace morph_basis_detail;
  assert(V_rest.cols() == 3 && "V_rest must be #V by 3");
  MorphBasis out;
  out.status = check_frames(frames, V_rest);
  if (!out.status.ok()) return out;
  const Eigen::Index F = static_cast<Eigen::Index>(frames.size()), n = V_rest.rows();
  out.mean = Eigen::MatrixXd::Zero(n, 3);
  for (const Eigen::MatrixXd& X : frames) out.mean += X;
  out.mean = out.mean / static_cast<double>(F) - V_rest;
  // Blocks of c vertices: F × 3c doubles each.
  const Eigen::Index c = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(opt.block_bytes / (24.0 * F)), 1, std::max<Eigen::Index>(n, 1));

  // Gram matrix of the centered displacements (lower triangle), one block at a time.
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(F, F), B;
  for (Eigen::Index v0 = 0; v0 < n; v0 += c) {
    displacement_block(frames, V_rest, out.mean, v0, std::min(c, n - v0), &B);
    G.selfadjointView<Eigen::Lower>().rankUpdate(B);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(G);
  if (es.info() != Eigen::Success) {
    out.status = Status::error(StatusCode::NumericalError, "morph basis: the eigen-decomposition of the frames' Gram matrix failed");
    return out;
  }
  // Eigenvalues ascend. Keep the largest ones above the numerical noise of the Gram matrix
  // (λ ≤ 1e-13·λ_max: a component of relative size ~3e-7, below float storage anyway).
  const Eigen::VectorXd& lambda = es.eigenvalues();
  const double lambda_max = F > 0 ? std::max(lambda[F - 1], 0.0) : 0.0;
  int K = 0;
  while (K < opt.max_components && K < F && lambda[F - 1 - K] > 1e-13 * lambda_max && lambda[F - 1 - K] > 0) ++K;
  out.sigma.resize(K);
  Eigen::MatrixXd Vk(F, K);
  for (int k = 0; k < K; ++k) {
    out.sigma[k] = std::sqrt(lambda[F - 1 - k]);
    Vk.col(k) = es.eigenvectors().col(F - 1 - k);
  }
  out.weights = Vk * out.sigma.asDiagonal();
  const Eigen::MatrixXd Vk_scaled = Vk * out.sigma.cwiseInverse().asDiagonal();

  // Components (Dᵀ v_k / σ_k) and the max error for every k, block by block.
  out.components.resize(3 * n, K);
  Eigen::VectorXd err2 = Eigen::VectorXd::Zero(K + 1);
  for (Eigen::Index v0 = 0; v0 < n; v0 += c) {
    const Eigen::Index cc = std::min(c, n - v0);
    displacement_block(frames, V_rest, out.mean, v0, cc, &B);
    out.components.middleRows(3 * v0, 3 * cc).noalias() = B.transpose() * Vk_scaled;
    err2[0] = std::max(err2[0], max_vertex_norm2(B));
    for (int k = 0; k < K; ++k) {
      B.noalias() -= out.weights.col(k) * out.components.col(k).segment(3 * v0, 3 * cc).transpose();
      err2[k + 1] = std::max(err2[k + 1], max_vertex_norm2(B));
    }
  }
  out.max_error = err2.cwiseSqrt();
  // Sign convention: the largest-magnitude coordinate of each component is positive.
  for (int k = 0; k < K; ++k) {
    Eigen::Index at = 0;
    out.components.col(k).cwiseAbs().maxCoeff(&at);
    if (out.components(at, k) < 0) {
      out.components.col(k) *= -1;
      out.weights.col(k) *= -1;
    }
  }
  if (!out.components.allFinite() || !out.weights.allFinite())
    out.status = Status::error(StatusCode::NumericalError, "morph basis: the components are not finite");
  return out;
}

int morph_basis_size(const MorphBasis& basis, double tolerance) {
  for (Eigen::Index k = 0; k < basis.max_error.size(); ++k)
    if (basis.max_error[k] <= tolerance) return static_cast<int>(k);
  return -1;
}

}  // namespace mm
