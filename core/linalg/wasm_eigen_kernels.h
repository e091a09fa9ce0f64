// WebAssembly SIMD for Eigen's dense double products (issue 18).
//
// Eigen 3.4 has no wasm packet math, so in wasm its dense products ran one value at a time:
//   - matrix × vector (GEMV): Spectra's Lanczos spends most of its own time there (the
//     reorthogonalisation f −= V (Vᵀ f)): 36 % of the wasm foundation bench, and the reason eigs
//     ran 1.4× native in wasm;
//   - matrix × matrix (GEMM's micro-kernel, gebp): 22 % of the wasm retarget bench (the MFS
//     systems), the transfer's coupled bases.
//
// This header declares explicit specialisations of Eigen's kernels for double:
// `general_matrix_vector_product<...>::run` (column-major and row-major, no conjugation) and
// `gebp_kernel<double, double, long, blas_data_mapper<double, long, ColMajor>, 1, 4>::operator()`
// (the micro-kernel the scalar build instantiates: one row by four columns of packed blocks). The
// wasm build force-includes it in every C++ translation unit that sees Eigen
// (cmake/dependencies.cmake, `-include`), so every TU calls the same definition:
// wasm_eigen_kernels.cpp, compiled with -msimd128. Natively nothing changes (Eigen's SSE/AVX
// kernels run).
//
// Every kernel keeps the order of the sums of Eigen's scalar kernel, so wasm's results are the
// same bits as before (tests/linalg_test.cpp checks the orders in both builds; a harness of 600
// shapes hashed the results of Eigen's scalar kernels and of these, equal):
//   GEMV column-major  per row, c = Σ_j A(i,j) b_j over a block of columns in order (the block
//                      width as Eigen picks it), then res_i += alpha·c (lanes: two rows) — also
//                      the order of Eigen's SSE2 kernel, so native's bits too;
//   GEMV row-major     per row, one sum over j in order, then res_i += alpha·c (lanes: two rows;
//                      Eigen's SSE2 kernel sums even and odd j apart, so native differs here);
//   gebp               per result entry, even and odd k of the peeled part (a multiple of 8) in
//                      two sums, added, the remaining k, then r += alpha·c (lanes: two columns).
// Keeping wasm's bits matters: the part transfer amplifies last-bit changes (a paw's landmark
// gate at ±0.05 %, the page's automatic parts on the cat; thirty-fifth session, docs/bench.md).
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

template <>
EIGEN_DONT_INLINE void gebp_kernel<double, double, long, blas_data_mapper<double, long, ColMajor, 0, 1>, 1, 4, false,
                                   false>::operator()(const blas_data_mapper<double, long, ColMajor, 0, 1>& res,
                                                      const double* blockA, const double* blockB, long rows, long depth,
                                                      long cols, double alpha, long strideA, long strideB, long offsetA,
                                                      long offsetB);

}  // namespace internal
}  // namespace Eigen
#endif
