#include "linalg/polar.h"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace mm {

Polar3 polar_decomposition(const Eigen::Matrix3d& M) {
  Polar3 out;
  if (!M.allFinite()) {
    out.R.setIdentity();
    out.S = M;
    out.singular_values.setConstant(std::numeric_limits<double>::quiet_NaN());
    return out;
  }
  // Full (not thin) U and V so that rank-deficient M still gives a rotation.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  Eigen::Vector3d sigma = svd.singularValues();
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((U * V.transpose()).determinant() < 0) {
    D(2, 2) = -1;  // flip the direction of the smallest singular value
    sigma[2] = -sigma[2];
  }
  out.R = U * D * V.transpose();
  out.S = out.R.transpose() * M;
  out.S = 0.5 * (out.S + out.S.transpose()).eval();
  out.singular_values = sigma;
  return out;
}

}  // namespace mm
