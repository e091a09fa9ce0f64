// WebAssembly SIMD for Eigen's dense matrix × vector products (issue 18).
//
// Eigen 3.4 has no wasm packet math, so in wasm its GEMV ran one value at a time. Spectra's
// Lanczos spends most of its own time there (the reorthogonalisation f −= V (Vᵀ f)): 35 % of the
// wasm foundation bench, and the reason eigs ran 1.4× native in wasm.
//
// This header declares explicit specialisations of Eigen's two double GEMV kernels
// (`general_matrix_vector_product<...>::run`, column-major and row-major, no conjugation). The wasm
// build force-includes it in every C++ translation unit that sees Eigen (cmake/dependencies.cmake,
// `-include`), so every TU calls the same definition: wasm_gemv.cpp, compiled with -msimd128.
// Natively nothing changes (Eigen's SSE/AVX kernels run).
//
// The kernels sum in exactly the order of Eigen's SSE2 kernels (two-lane packets), so wasm's
// products now give native's bits:
//   column-major  per row, c = Σ_j A(i,j) b_j over a block of columns in order (the block width as
//                 Eigen picks it), then res_i += alpha·c — the same order as Eigen's scalar kernel;
//   row-major     per row, two partial sums over even and odd j, added, the odd tail, then
//                 res_i += alpha·c — Eigen's order for a two-lane packet (SSE2), which wasm's
//                 scalar kernel did not have.
#pragma once

#if defined(__EMSCRIPTEN__) && defined(__cplusplus)
#include <Eigen/Core>

namespace Eigen {
namespace internal {

template <>
EIGEN_DONT_INLINE void general_matrix_vector_product<
    long, double, const_blas_data_mapper<double, long, ColMajor>, ColMajor, false, double,
    const_blas_data_mapper<double, long, RowMajor>, false, 0>::run(long rows, long cols,
                                                                   const const_blas_data_mapper<double, long, ColMajor>& lhs,
                                                                   const const_blas_data_mapper<double, long, RowMajor>& rhs,
                                                                   double* res, long resIncr, double alpha);

template <>
EIGEN_DONT_INLINE void general_matrix_vector_product<
    long, double, const_blas_data_mapper<double, long, RowMajor>, RowMajor, false, double,
    const_blas_data_mapper<double, long, ColMajor>, false, 0>::run(long rows, long cols,
                                                                   const const_blas_data_mapper<double, long, RowMajor>& lhs,
                                                                   const const_blas_data_mapper<double, long, ColMajor>& rhs,
                                                                   double* res, long resIncr, double alpha);

}  // namespace internal
}  // namespace Eigen
#endif
