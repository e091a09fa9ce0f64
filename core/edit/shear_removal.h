// Shear removal of a deformation gradient (paper 001 Sec. 4): the rotation R of the polar
// decomposition M = R S, i.e. R = U Vᵀ from the SVD M = U W Vᵀ; the uniform scale of Eq. 10 is
// s = sqrt((σ1² + σ2² + σ3²)/3) = ||M||_F / √3 and needs no decomposition.
#pragma once

#include <Eigen/Core>

namespace mm {

// For well-conditioned, orientation-preserving M the closed form R = M V diag(1/σ) Vᵀ from the
// eigen-decomposition of MᵀM (closed-form 3x3 eigen solver) is ~10× faster than a Jacobi SVD
// and, after one Newton polar step, agrees with it to ~1e-15; near-singular (σ3² < 1e-6 σ1²) or reflected M go through
// linalg/polar.h (which moves the reflection into S). Non-finite M gives the identity.
Eigen::Matrix3d rotation_part(const Eigen::Matrix3d& M);

}  // namespace mm
