// WebAssembly SIMD definitions of Eigen's double GEMV kernels (declared in wasm_gemv.h, which the
// wasm build force-includes everywhere). Natively this file is empty.
#include "linalg/wasm_gemv.h"

#if defined(__EMSCRIPTEN__)
#if !defined(__wasm_simd128__)
#error "wasm_gemv.cpp must be compiled with -msimd128 (CMakeLists.txt)"
#endif
#include <algorithm>

#include <wasm_simd128.h>

namespace Eigen {
namespace internal {

namespace {

inline v128_t madd(v128_t a, v128_t b, v128_t c) { return wasm_f64x2_add(wasm_f64x2_mul(a, b), c); }

// R consecutive pairs of rows (2R rows) starting at row i, over columns [j0, j1):
// res[i..] = (Σ_j A(i.., j) b_j)·alpha + res[i..], each lane summing its own row in column order.
template <int R>
inline void colmajor_rows(const double* A, long lda, const double* b, long bstride, long i, long j0, long j1,
                          v128_t va, double* res) {
  v128_t c[R];
  for (int r = 0; r < R; ++r) c[r] = wasm_f64x2_splat(0.0);
  for (long j = j0; j < j1; ++j) {
    const v128_t bj = wasm_f64x2_splat(b[j * bstride]);
    const double* a = A + i + j * lda;
    for (int r = 0; r < R; ++r) c[r] = madd(wasm_v128_load(a + 2 * r), bj, c[r]);
  }
  for (int r = 0; r < R; ++r)
    wasm_v128_store(res + i + 2 * r, madd(c[r], va, wasm_v128_load(res + i + 2 * r)));
}

// R rows starting at row i of a row-major A: per row two partial sums (even / odd columns),
// added, then the odd column, then res_i += alpha·sum — Eigen's order for SSE2's Packet2d.
template <int R>
inline void rowmajor_rows(const double* A, long lda, const double* b, long cols, long i, double alpha, double* res,
                          long resIncr) {
  v128_t c[R];
  const double* a[R];
  for (int r = 0; r < R; ++r) {
    c[r] = wasm_f64x2_splat(0.0);
    a[r] = A + (i + r) * lda;
  }
  long j = 0;
  for (; j + 2 <= cols; j += 2) {
    const v128_t bj = wasm_v128_load(b + j);
    for (int r = 0; r < R; ++r) c[r] = madd(wasm_v128_load(a[r] + j), bj, c[r]);
  }
  double cc[R];
  for (int r = 0; r < R; ++r) cc[r] = wasm_f64x2_extract_lane(c[r], 0) + wasm_f64x2_extract_lane(c[r], 1);
  for (; j < cols; ++j)
    for (int r = 0; r < R; ++r) cc[r] += a[r][j] * b[j];
  for (int r = 0; r < R; ++r) res[(i + r) * resIncr] += alpha * cc[r];
}

}  // namespace

template <>
EIGEN_DONT_INLINE void general_matrix_vector_product<
    long, double, const_blas_data_mapper<double, long, ColMajor>, ColMajor, false, double,
    const_blas_data_mapper<double, long, RowMajor>, false, 0>::run(long rows, long cols,
                                                                   const const_blas_data_mapper<double, long, ColMajor>& lhs,
                                                                   const const_blas_data_mapper<double, long, RowMajor>& rhs,
                                                                   double* res, long resIncr, double alpha) {
  eigen_internal_assert(resIncr == 1);
  const double* A = lhs.data();
  const long lda = lhs.stride();
  const double* b = rhs.data();
  const long bstride = rhs.stride();
  // Eigen's column blocking (GeneralMatrixVector.h): res is updated once per block, so the block
  // width is part of the order of the sums.
  const long block_cols = cols < 128 ? cols : (lda * static_cast<long>(sizeof(double)) < 32000 ? 16 : 4);
  const v128_t va = wasm_f64x2_splat(alpha);
  for (long j0 = 0; j0 < cols; j0 += block_cols) {
    const long j1 = std::min(j0 + block_cols, cols);
    long i = 0;
    for (; i + 8 <= rows; i += 8) colmajor_rows<4>(A, lda, b, bstride, i, j0, j1, va, res);
    for (; i + 2 <= rows; i += 2) colmajor_rows<1>(A, lda, b, bstride, i, j0, j1, va, res);
    for (; i < rows; ++i) {
      double c = 0;
      for (long j = j0; j < j1; ++j) c += A[i + j * lda] * b[j * bstride];
      res[i] += alpha * c;
    }
  }
}

template <>
EIGEN_DONT_INLINE void general_matrix_vector_product<
    long, double, const_blas_data_mapper<double, long, RowMajor>, RowMajor, false, double,
    const_blas_data_mapper<double, long, ColMajor>, false, 0>::run(long rows, long cols,
                                                                   const const_blas_data_mapper<double, long, RowMajor>& lhs,
                                                                   const const_blas_data_mapper<double, long, ColMajor>& rhs,
                                                                   double* res, long resIncr, double alpha) {
  eigen_internal_assert(rhs.stride() == 1);
  const double* A = lhs.data();
  const long lda = lhs.stride();
  const double* b = rhs.data();
  long i = 0;
  for (; i + 4 <= rows; i += 4) rowmajor_rows<4>(A, lda, b, cols, i, alpha, res, resIncr);
  for (; i < rows; ++i) rowmajor_rows<1>(A, lda, b, cols, i, alpha, res, resIncr);
}

}  // namespace internal
}  // namespace Eigen
#endif
