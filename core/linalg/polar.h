// Robust 3x3 polar decomposition M = R·S with R a proper rotation (det R = +1) and S
// symmetric. Used for shear removal (paper 001 Sec. 4) and linearized rotations.
#pragma once

#include <Eigen/Core>

namespace mm {

struct Polar3 {
  Eigen::Matrix3d R;              // rotation, det = +1
  Eigen::Matrix3d S;              // symmetric stretch, M = R S
  Eigen::Vector3d singular_values;// of M, descending; the last one is negated when det M < 0
};

// Via SVD M = UΣVᵀ: R = U·diag(1,1,det(UVᵀ))·Vᵀ, S = Rᵀ M. Handles rank-deficient and
// reflected M (the reflection is moved into S). Non-finite M gives R = I, S = M.
Polar3 polar_decomposition(const Eigen::Matrix3d& M);

}  // namespace mm
