// The fundamental solution of the 3D Laplace equation and its derivatives, evaluated between
// points x and singularity points q: the component functions of the method of fundamental
// solutions (paper 002 Eq. 2: k(p, q) = 1/(4π‖p − q‖)).
//
// Every function here is harmonic in x away from q, so any linear combination f(x) = K(x)W
// is a harmonic map; derivatives are taken with respect to x.
#pragma once

#include <Eigen/Core>

namespace mm {

// K (#X by #Q): K(i, a) = 1 / (4π ‖X_i − Q_a‖). X: #X by 3, Q: #Q by 3. Points must differ
// from every q (singularities lie outside the shape); a coincident pair gives Inf.
Eigen::MatrixXd mfs_kernel(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q);

// D (3·#X by #Q): rows 3i+d hold ∂k(X_i, Q_a)/∂x_d = −(X_i − Q_a)_d / (4π r³).
// For coefficients W (#Q by 3), the 3×3 block D.middleRows(3i, 3)·W is Jᵀ, the transposed
// Jacobian of f = K W at X_i (paper 002 Eq. 4: Jᵀ = D W).
Eigen::MatrixXd mfs_gradient(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q);

// H (6·#X by #Q): second derivatives ∂²k/∂x_a∂x_b = (3 d_a d_b / r² − δ_ab) / (4π r³),
// d = X_i − Q_a, stored per point as rows (xx, yy, zz, √2·xy, √2·xz, √2·yz) so that the squared
// norm of H.middleRows(6i, 6)·W equals Σ_c ‖Hessian of f_c at X_i‖²_F (paper 002 Eq. 7).
Eigen::MatrixXd mfs_hessian(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q);

// Mtᵀ B for Mt (k by n) and B (k by 3): the per-frame products of the retargeting (V = Kt Wt,
// Uᵀ bs, Wt = [Ga gp Gb] [Ys; p; d̂]) with the big operand stored transposed, so that each output row reads one contiguous
// column. A plain loop with a fixed summation order: for three right-hand columns it is faster
// than a general matrix product (no packing of the big operand on every call), natively and in
// WebAssembly without SIMD, and both platforms sum in the same order.
Eigen::MatrixXd transposed_times_n3(const Eigen::MatrixXd& Mt, const Eigen::MatrixXd& B);

}  // namespace mm
