#include "retarget/mfs_kernel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/threads.h"

namespace mm {

namespace {
#if defined(__SSE2__) || defined(__wasm_simd128__)
#define MM_MFS_PAIRS 1
// Two doubles, one per SIMD lane (GCC/Clang vector extension: + and × work lane by lane).
typedef double MfsPair __attribute__((vector_size(16)));
inline MfsPair mfs_load(const double* p) {
  MfsPair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
#else
#define MM_MFS_PAIRS 0
#endif
}  // namespace

namespace retarget_detail {
constexpr double kInv4Pi = 1.0 / (4.0 * M_PI);
}

Eigen::MatrixXd mfs_kernel(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q) {
  Eigen::MatrixXd K(X.rows(), Q.rows());
  for (int a = 0; a < Q.rows(); ++a) {
    const double qx = Q(a, 0), qy = Q(a, 1), qz = Q(a, 2);
    for (int i = 0; i < X.rows(); ++i) {
      const double dx = X(i, 0) - qx, dy = X(i, 1) - qy, dz = X(i, 2) - qz;
      K(i, a) = retarget_detail::kInv4Pi / std::sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  return K;
}

Eigen::MatrixXd mfs_gradient(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q) {
  Eigen::MatrixXd D(3 * X.rows(), Q.rows());
  for (int a = 0; a < Q.rows(); ++a)
    for (int i = 0; i < X.rows(); ++i) {
      const Eigen::Vector3d d = X.row(i) - Q.row(a);
      const double r = d.norm();
      const double c = -retarget_detail::kInv4Pi / (r * r * r);
      D(3 * i + 0, a) = c * d[0];
      D(3 * i + 1, a) = c * d[1];
      D(3 * i + 2, a) = c * d[2];
    }
  return D;
}

Eigen::MatrixXd mfs_hessian(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Q) {
  Eigen::MatrixXd H(6 * X.rows(), Q.rows());
  const double s2 = std::sqrt(2.0);
  for (int a = 0; a < Q.rows(); ++a)
    for (int i = 0; i < X.rows(); ++i) {
      const Eigen::Vector3d d = X.row(i) - Q.row(a);
      const double r2 = d.squaredNorm();
      const double c = retarget_detail::kInv4Pi / (r2 * std::sqrt(r2));
      const double t = 3.0 / r2;
      H(6 * i + 0, a) = c * (t * d[0] * d[0] - 1);
      H(6 * i + 1, a) = c * (t * d[1] * d[1] - 1);
      H(6 * i + 2, a) = c * (t * d[2] * d[2] - 1);
      H(6 * i + 3, a) = s2 * c * t * d[0] * d[1];
      H(6 * i + 4, a) = s2 * c * t * d[0] * d[2];
      H(6 * i + 5, a) = s2 * c * t * d[1] * d[2];
    }
  return H;
}

Eigen::MatrixXd transposed_times_n3(const Eigen::MatrixXd& Mt, const Eigen::MatrixXd& B) {
  const Eigen::Index k = Mt.rows(), n = Mt.cols();
  // B's columns, each contiguous: a pair of consecutive terms is one two-lane load.
  std::vector<double> bx(k), by(k), bz(k);
  for (Eigen::Index i = 0; i < k; ++i) bx[i] = B(i, 0), by[i] = B(i, 1), bz[i] = B(i, 2);
  Eigen::MatrixXd out(n, 3);
  // Columns are independent: split in blocks of at least ~1e5 multiply-adds across the task
  // threads (the per-frame vertex product of the retargeter; bit-identical for any split).
  const long min_cols = std::max<long>(1, 100000 / std::max<long>(1, 3 * static_cast<long>(k)));
  parallel_blocks(static_cast<long>(n), min_cols, [&](long begin, long end) {
    for (Eigen::Index j = begin; j < end; ++j) {
      const double* m = Mt.col(j).data();
      // Two chains per coordinate: even terms in chain 0, odd terms in chain 1, summed in order,
      // then chain 0 + chain 1. With SIMD the two chains are the two lanes of one vector (the
      // same multiplications and additions per lane, so the same bits as the scalar loop).
      double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
      Eigen::Index i = 0;
#if MM_MFS_PAIRS
      MfsPair x = {0, 0}, y = {0, 0}, z = {0, 0};
      for (; i + 1 < k; i += 2) {
        const MfsPair mi = mfs_load(m + i);
        x += mi * mfs_load(&bx[i]);
        y += mi * mfs_load(&by[i]);
        z += mi * mfs_load(&bz[i]);
      }
      x0 = x[0], x1 = x[1], y0 = y[0], y1 = y[1], z0 = z[0], z1 = z[1];
#else
      for (; i + 1 < k; i += 2) {
        x0 += m[i] * bx[i];
        y0 += m[i] * by[i];
        z0 += m[i] * bz[i];
        x1 += m[i + 1] * bx[i + 1];
        y1 += m[i + 1] * by[i + 1];
        z1 += m[i + 1] * bz[i + 1];
      }
#endif
      if (i < k) {
        x0 += m[i] * bx[i];
        y0 += m[i] * by[i];
        z0 += m[i] * bz[i];
      }
      out(j, 0) = x0 + x1;
      out(j, 1) = y0 + y1;
      out(j, 2) = z0 + z1;
    }
  });
  return out;
}

}  // namespace mm
