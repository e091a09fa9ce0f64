// WebAssembly SIMD definitions of Eigen's double GEMV and gebp kernels (declared in
// wasm_eigen_kernels.h, which the wasm build force-includes everywhere). Natively this file is empty.
#include "linalg/wasm_eigen_kernels.h"

#if defined(__EMSCRIPTEN__)
#if !defined(__wasm_simd128__)
#error "wasm_eigen_kernels.cpp must be compiled with -msimd128 (CMakeLists.txt)"
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

// R rows starting at row i of a row-major A, one row per lane: per row one sum over j in order,
// then res_i += alpha·sum — Eigen's scalar order (a single-lane packet), so wasm keeps its bits.
template <int R>
inline void rowmajor_rows(const double* A, long lda, const double* b, long cols, long i, double alpha, double* res,
                          long resIncr) {
  static_assert(R % 2 == 0, "rows in lane pairs");
  v128_t c[R / 2];
  const double* a[R];
  for (int r = 0; r < R; ++r) a[r] = A + (i + r) * lda;
  for (int q = 0; q < R / 2; ++q) c[q] = wasm_f64x2_splat(0.0);
  for (long j = 0; j < cols; ++j) {
    const v128_t bj = wasm_f64x2_splat(b[j]);
    for (int q = 0; q < R / 2; ++q) c[q] = madd(wasm_f64x2_make(a[2 * q][j], a[2 * q + 1][j]), bj, c[q]);
  }
  for (int q = 0; q < R / 2; ++q) {
    res[(i + 2 * q) * resIncr] += alpha * wasm_f64x2_extract_lane(c[q], 0);
    res[(i + 2 * q + 1) * resIncr] += alpha * wasm_f64x2_extract_lane(c[q], 1);
  }
}

// gebp, R rows (i, i+1, ...) by the four columns of the packed panel blB (4 values per k), as
// Eigen's scalar kernel sums them: even k of the peeled part (a multiple of 8) in c, odd k in d,
// c + d, the remaining k in c, then r = c·alpha + r. The lanes hold columns (two per vector).
template <int R>
inline void gebp_rows_x4(const double* blockA, long strideA, long offsetA, long i, const double* blB, long depth,
                         long peeled_kc, double alpha, double* res, long ld, long j2) {
  const double* a[R];
  v128_t c[R][2], d[R][2];
  for (int r = 0; r < R; ++r) {
    a[r] = blockA + (i + r) * strideA + offsetA;
    c[r][0] = c[r][1] = d[r][0] = d[r][1] = wasm_f64x2_splat(0.0);
  }
  long k = 0;
  for (; k < peeled_kc; k += 2) {
    const v128_t b0 = wasm_v128_load(blB + 4 * k), b1 = wasm_v128_load(blB + 4 * k + 2);
    const v128_t e0 = wasm_v128_load(blB + 4 * k + 4), e1 = wasm_v128_load(blB + 4 * k + 6);
    for (int r = 0; r < R; ++r) {
      const v128_t av = wasm_v128_load64_splat(a[r] + k), aw = wasm_v128_load64_splat(a[r] + k + 1);
      c[r][0] = wasm_f64x2_add(c[r][0], wasm_f64x2_mul(av, b0));
      c[r][1] = wasm_f64x2_add(c[r][1], wasm_f64x2_mul(av, b1));
      d[r][0] = wasm_f64x2_add(d[r][0], wasm_f64x2_mul(aw, e0));
      d[r][1] = wasm_f64x2_add(d[r][1], wasm_f64x2_mul(aw, e1));
    }
  }
  for (int r = 0; r < R; ++r) {
    c[r][0] = wasm_f64x2_add(c[r][0], d[r][0]);
    c[r][1] = wasm_f64x2_add(c[r][1], d[r][1]);
  }
  for (; k < depth; ++k) {
    const v128_t b0 = wasm_v128_load(blB + 4 * k), b1 = wasm_v128_load(blB + 4 * k + 2);
    for (int r = 0; r < R; ++r) {
      const v128_t av = wasm_v128_load64_splat(a[r] + k);
      c[r][0] = wasm_f64x2_add(c[r][0], wasm_f64x2_mul(av, b0));
      c[r][1] = wasm_f64x2_add(c[r][1], wasm_f64x2_mul(av, b1));
    }
  }
  const v128_t va = wasm_f64x2_splat(alpha);
  for (int r = 0; r < R; ++r) {
    const v128_t s0 = wasm_f64x2_mul(c[r][0], va), s1 = wasm_f64x2_mul(c[r][1], va);
    double* out = res + (i + r) + j2 * ld;
    out[0] += wasm_f64x2_extract_lane(s0, 0);
    out[ld] += wasm_f64x2_extract_lane(s0, 1);
    out[2 * ld] += wasm_f64x2_extract_lane(s1, 0);
    out[3 * ld] += wasm_f64x2_extract_lane(s1, 1);
  }
}

}  // namespace

template <>
EIGEN_DONT_INLINE void gebp_kernel<double, double, long, blas_data_mapper<double, long, ColMajor, 0, 1>, 1, 4, false,
                                   false>::operator()(const blas_data_mapper<double, long, ColMajor, 0, 1>& res,
                                                      const double* blockA, const double* blockB, long rows, long depth,
                                                      long cols, double alpha, long strideA, long strideB, long offsetA,
                                                      long offsetB) {
  if (strideA == -1) strideA = depth;
  if (strideB == -1) strideB = depth;
  double* R = const_cast<double*>(res.data());  // the mapper writes through it (Scalar = double)
  const long ld = res.stride();
  const long packet_cols4 = (cols / 4) * 4;
  const long peeled_kc = depth & ~7L;  // Eigen's peeling by pk = 8
  for (long j2 = 0; j2 < packet_cols4; j2 += 4) {
    const double* blB = blockB + j2 * strideB + offsetB * 4;
    long i = 0;
    for (; i + 2 <= rows; i += 2) gebp_rows_x4<2>(blockA, strideA, offsetA, i, blB, depth, peeled_kc, alpha, R, ld, j2);
    for (; i < rows; ++i) gebp_rows_x4<1>(blockA, strideA, offsetA, i, blB, depth, peeled_kc, alpha, R, ld, j2);
  }
  // The remaining columns, one at a time: one sum over every k in order (Eigen's kernel has no
  // second sum here).
  for (long j2 = packet_cols4; j2 < cols; ++j2) {
    const double* blB = blockB + j2 * strideB + offsetB;
    for (long i = 0; i < rows; ++i) {
      const double* a = blockA + i * strideA + offsetA;
      double c = 0;
      for (long k = 0; k < depth; ++k) c = c + a[k] * blB[k];
      R[i + j2 * ld] += c * alpha;
    }
  }
}

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
  for (; i + 2 <= rows; i += 2) rowmajor_rows<2>(A, lda, b, cols, i, alpha, res, resIncr);
  for (; i < rows; ++i) {
    double c = 0;
    for (long j = 0; j < cols; ++j) c = A[i * lda + j] * b[j] + c;
    res[i * resIncr] += alpha * c;
  }
}

}  // namespace internal
}  // namespace Eigen
#endif
