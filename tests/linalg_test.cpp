#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>

#include "linalg/block_lanczos.h"
#include "linalg/polar.h"
#include "linalg/spd_solver.h"
#include "linalg/supernodal_cholesky.h"
#include "io/asset.h"
#include "operators/operators.h"
#include "test_meshes.h"
#include "test_support.h"

namespace mm {

TEST(SpdSolver, FactorOnceSolveManyRightHandSides) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(3, &V, &F);
  const SparseMatrix A = cotan_stiffness(V, F) + mass_matrix(V, F);
  SpdSolver solver;
  ASSERT_TRUE(solver.factor(A).ok());
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  Eigen::MatrixXd B(V.rows(), 3);
  for (int i = 0; i < B.size(); ++i) B.data()[i] = g(rng);
  Eigen::MatrixXd X;
  ASSERT_TRUE(solver.solve(B, &X).ok());
  EXPECT_LT((A * X - B).norm() / B.norm(), 1e-10);
  // Same pattern, new values: refactor skips analysis and still solves.
  const SparseMatrix A2 = cotan_stiffness(V, F) + 2.0 * mass_matrix(V, F);
  ASSERT_TRUE(solver.refactor(A2).ok());
  Eigen::MatrixXd inplace = B;
  solver.solve_in_place(inplace);
  EXPECT_LT((A2 * inplace - B).norm() / B.norm(), 1e-10);
}

TEST(SpdSolver, SingularOrIndefiniteMatrixIsReportedNotSolved) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(2, &V, &F);
  SpdSolver solver;
  // W alone is singular (constants in its null space).
  const Status s = solver.factor(cotan_stiffness(V, F));
  EXPECT_EQ(s.code, StatusCode::FactorizationFailed);
  EXPECT_FALSE(solver.factored());
  Eigen::MatrixXd X;
  EXPECT_EQ(solver.solve(Eigen::MatrixXd::Ones(V.rows(), 1), &X).code, StatusCode::InvalidArgument);
  const SparseMatrix negative = -mass_matrix(V, F);
  EXPECT_EQ(solver.factor(negative).code, StatusCode::FactorizationFailed);
}

// The supernodal factor's column counts (Gilbert–Ng–Peyton, O(nnz(A) α)) equal the row-subtree
// counts they replaced (O(nnz(L)), walking every row's subtree of the elimination tree), on a
// 2-ring matrix of a real mesh in a random and in the AMD-free natural order, and on a forest
// (three disconnected blocks, one a single isolated vertex).
TEST(SupernodalSymbolic, ColumnCountsEqualRowSubtreeCounts) {
  using namespace supernodal_detail;
  const io::LoadResult lr = io::load_asset(test::data_path("edit/decimated-knight.ply"));
  ASSERT_TRUE(lr.status.ok()) << lr.status.message;
  const Mesh m = lr.asset.mesh();
  const SparseMatrix W = cotan_stiffness(m.V, m.F);
  SparseMatrix I(W.rows(), W.cols());
  I.setIdentity();
  const SparseMatrix K = SparseMatrix(W.transpose()) * W + I;
  const int nk = static_cast<int>(K.rows());
  // A forest: the knight's matrix, a copy of it, and one isolated vertex.
  std::vector<Eigen::Triplet<double>> t;
  for (int copy = 0; copy < 2; ++copy)
    for (int j = 0; j < nk; ++j)
      for (SparseMatrix::InnerIterator it(K, j); it; ++it) t.emplace_back(copy * nk + it.row(), copy * nk + j, it.value());
  t.emplace_back(2 * nk, 2 * nk, 1.0);
  SparseMatrix forest(2 * nk + 1, 2 * nk + 1);
  forest.setFromTriplets(t.begin(), t.end());
  std::mt19937 rng(5);
  int checked = 0;
  for (const SparseMatrix* A : {&K, static_cast<const SparseMatrix*>(&forest)})
    for (int shuffled = 0; shuffled < 2; ++shuffled) {
      const int n = static_cast<int>(A->rows());
      const SparseMatrix L = A->triangularView<Eigen::Lower>();
      std::vector<int> p(n);
      for (int i = 0; i < n; ++i) p[i] = i;
      if (shuffled) std::shuffle(p.begin(), p.end(), rng);
      // Postorder the elimination tree of the permuted matrix, as the factorization does.
      const std::vector<int> order = sn_postorder(sn_elimination_tree(sn_permuted_triangle(L, p, true)));
      std::vector<int> q(n);
      for (int k = 0; k < n; ++k) q[order[k]] = k;
      for (int i = 0; i < n; ++i) p[i] = q[p[i]];
      const SparseMatrix C = sn_permuted_triangle(L, p, false), U = sn_permuted_triangle(L, p, true);
      const std::vector<int> parent = sn_elimination_tree(U);
      for (int j = 0; j < n; ++j) ASSERT_TRUE(parent[j] == -1 || parent[j] > j);
      std::vector<int> expected(n, 0), mark(n, -1);
      for (int k = 0; k < n; ++k) {
        mark[k] = k;
        for (SparseMatrix::InnerIterator it(U, k); it; ++it)
          for (int j = static_cast<int>(it.row()); j < k && mark[j] != k; j = parent[j]) {
            ++expected[j];
            mark[j] = k;
          }
      }
      EXPECT_EQ(sn_column_counts(C, parent), expected) << "matrix of " << n << (shuffled ? ", shuffled" : "");
      ++checked;
    }
  EXPECT_EQ(checked, 4);
}

TEST(Polar, RecoversRotationAndSymmetricStretch) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d R0 =
        Eigen::AngleAxisd(3.0 * u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    Eigen::Matrix3d S0 = Eigen::Matrix3d::Random();
    S0 = S0 * S0.transpose() + 0.1 * Eigen::Matrix3d::Identity();  // SPD stretch
    const Polar3 p = polar_decomposition(R0 * S0);
    EXPECT_LT((p.R - R0).norm(), 1e-9);
    EXPECT_LT((p.S - S0).norm(), 1e-9);
    EXPECT_NEAR(p.R.determinant(), 1.0, 1e-12);
  }
}

TEST(Polar, ReflectionAndRankDeficiencyStillGiveProperRotations) {
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1, 1, -1).asDiagonal();
  const Polar3 p = polar_decomposition(mirror);
  EXPECT_NEAR(p.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((p.R * p.S - mirror).norm(), 1e-12);
  EXPECT_LT(p.singular_values[2], 0.0);
  Eigen::Matrix3d flat = Eigen::Matrix3d::Zero();
  flat(0, 0) = 2;
  flat(1, 1) = 1;  // rank 2
  const Polar3 q = polar_decomposition(flat);
  EXPECT_NEAR(q.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((q.R * q.S - flat).norm(), 1e-12);
  const Polar3 z = polar_decomposition(Eigen::Matrix3d::Zero());
  EXPECT_NEAR(z.R.determinant(), 1.0, 1e-12);
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(polar_decomposition(bad).R.isIdentity());
}

// Block Lanczos on a dense symmetric operator with a known spectrum: a 12-fold top eigenvalue
// (three times the block size), a close pair, and a long tail; then a rank-3 operator, whose
// Krylov space runs out after one block (the rank-loss path), and a cancel.
TEST(BlockLanczos, KnownSpectrumWithMultipletsLargerThanTheBlock) {
  const int n = 400;
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  Eigen::MatrixXd G(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) G(i, j) = g(rng);
  const Eigen::MatrixXd U = Eigen::HouseholderQR<Eigen::MatrixXd>(G).householderQ();
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d[i] = i < 12 ? 10.0 : i == 12 ? 7.0 : i == 13 ? 7.0 - 1e-7 : 6.0 * std::pow(0.99, i);
  const Eigen::MatrixXd Op = U * d.asDiagonal() * U.transpose();
  BlockLanczosOptions o;
  o.nev = 16;
  o.block = 4;
  int calls = 0;
  const BlockLanczosResult r = block_lanczos(
      n, [&](const Eigen::MatrixXd& X, Eigen::MatrixXd* Y) { ++calls; *Y = Op * X; return true; }, o);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.values.size(), 16);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(r.values[i], d[i], 1e-9) << i;
  EXPECT_LT((r.vectors.transpose() * r.vectors - Eigen::MatrixXd::Identity(16, 16)).cwiseAbs().maxCoeff(), 1e-10);
  for (int i = 0; i < 16; ++i) EXPECT_LT((Op * r.vectors.col(i) - r.values[i] * r.vectors.col(i)).norm(), 1e-8) << i;
  EXPECT_EQ(r.applications, 4 * calls);

  // Rank 3: after the first block the rest of the space is Op's null space.
  const Eigen::MatrixXd Low = U.leftCols(3) * Eigen::Vector3d(3, 2, 1).asDiagonal() * U.leftCols(3).transpose();
  o.nev = 3;
  const BlockLanczosResult low = block_lanczos(
      n, [&](const Eigen::MatrixXd& X, Eigen::MatrixXd* Y) { *Y = Low * X; return true; }, o);
  ASSERT_TRUE(low.status.ok()) << low.status.message;
  EXPECT_NEAR(low.values[0], 3, 1e-10);
  EXPECT_NEAR(low.values[1], 2, 1e-10);
  EXPECT_NEAR(low.values[2], 1, 1e-10);
  EXPECT_TRUE(low.vectors.allFinite());

  // Cancel on the third block; too small a space is refused.
  calls = 0;
  const BlockLanczosResult c = block_lanczos(
      n, [&](const Eigen::MatrixXd& X, Eigen::MatrixXd* Y) { *Y = Op * X; return ++calls < 3; }, o);
  EXPECT_EQ(c.status.code, StatusCode::Cancelled);
  EXPECT_EQ(calls, 3);
  o.nev = 200;
  EXPECT_EQ(block_lanczos(n, [&](const Eigen::MatrixXd& X, Eigen::MatrixXd* Y) { *Y = Op * X; return true; }, o).status.code,
            StatusCode::InvalidArgument);
}

// Eigen's dense matrix × vector products sum in a documented order in each build
// (core/linalg/wasm_eigen_kernels.h): natively Eigen's SSE2 kernels, in wasm our SIMD kernels that
// replace Eigen's scalar ones and keep their order. Compared bit for bit with plain loops in that
// order. Sizes cross Eigen's column blocking (128 columns) and both its strides (a block of a
// larger matrix), odd and even lengths, and rows left over from the kernels' blocks of 8 and 4.
TEST(DenseProducts, MatrixVectorSumsInTheDocumentedOrder) {
#if defined(__AVX__)
  GTEST_SKIP() << "built with AVX: Eigen's four-lane kernels sum in another order";
#endif
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double alpha = 0.7310585786300049;
  int checked = 0;
  for (const int ld_extra : {0, 3, 5000}) {
    for (const int rows : {2, 3, 7, 8, 9, 17, 130}) {
      for (const int cols : {1, 2, 5, 16, 127, 128, 131, 300}) {
        Eigen::MatrixXd big(rows + ld_extra, cols);
        for (Eigen::Index j = 0; j < big.cols(); ++j)
          for (Eigen::Index i = 0; i < big.rows(); ++i) big(i, j) = u(rng);
        const auto A = big.topRows(rows);  // outer stride rows + ld_extra
        Eigen::VectorXd x(cols), xt(rows), y0(rows), y0t(cols);
        for (auto* v : {&x, &xt, &y0, &y0t})
          for (Eigen::Index i = 0; i < v->size(); ++i) (*v)(i) = u(rng);

        // Column-major: per row, c = Σ_j A(i,j) x_j over Eigen's column block, then y_i += alpha·c.
        Eigen::VectorXd y = y0, ref = y0;
        y.noalias() += alpha * A * x;
        const Eigen::Index lda = big.outerStride();
        const int block = cols < 128 ? cols : (lda * static_cast<Eigen::Index>(sizeof(double)) < 32000 ? 16 : 4);
        for (int j0 = 0; j0 < cols; j0 += block)
          for (int i = 0; i < rows; ++i) {
            double c = 0;
            for (int j = j0; j < std::min(j0 + block, cols); ++j) c = A(i, j) * x(j) + c;
            ref(i) = c * alpha + ref(i);
          }
        for (int i = 0; i < rows; ++i)
          ASSERT_EQ(y(i), ref(i)) << "A x, " << rows << " x " << cols << " stride " << lda << ", row " << i;

        // Row-major (Aᵀ x): natively (SSE2's two lanes) per row even and odd partial sums, added,
        // the odd tail; in wasm one sum in order (Eigen's scalar order, which our kernel keeps);
        // then y_i += alpha·c. (One column makes Aᵀ a single row: Eigen takes that as a dot
        // product, not a GEMV.)
        ++checked;
        if (cols == 1) continue;
        Eigen::VectorXd yt = y0t, reft = y0t;
        yt.noalias() += alpha * A.transpose() * xt;
        for (int i = 0; i < cols; ++i) {
#if defined(__EMSCRIPTEN__)
          double c = 0;
          for (int j = 0; j < rows; ++j) c = A(j, i) * xt(j) + c;
#else
          double s0 = 0, s1 = 0;
          int j = 0;
          for (; j + 2 <= rows; j += 2) {
            s0 = A(j, i) * xt(j) + s0;
            s1 = A(j + 1, i) * xt(j + 1) + s1;
          }
          double c = s0 + s1;
          for (; j < rows; ++j) c += A(j, i) * xt(j);
#endif
          reft(i) += alpha * c;
        }
        for (int i = 0; i < cols; ++i)
          ASSERT_EQ(yt(i), reft(i)) << "A' x, " << cols << " x " << rows << " stride " << lda << ", row " << i;
      }
    }
  }
  EXPECT_EQ(checked, 3 * 7 * 8);
}

// In wasm, Eigen's matrix × matrix micro-kernel is ours too (core/linalg/wasm_eigen_kernels.h) and
// keeps the order of Eigen's scalar kernel: per entry, the even and odd k of the peeled part (a
// multiple of 8) in two sums, added, the remaining k, then c·alpha added to the entry (four
// columns at a time; a fifth, sixth... column in one sum). Checked bit for bit at depths that fit
// one of Eigen's depth blocks. (Natively Eigen's SSE2 kernel blocks the sums differently.)
TEST(DenseProducts, WasmMatrixProductKeepsTheScalarKernelsOrder) {
#if !defined(__EMSCRIPTEN__)
  GTEST_SKIP() << "native build: Eigen's own vectorised kernel";
#else
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double alpha = -0.4142135623730951;
  int checked = 0;
  for (const int m : {2, 3, 9, 33})
    for (const int k : {2, 7, 8, 13, 16, 40, 64})
      for (const int n : {2, 4, 6, 9, 17}) {
        // Below 20 (k + m + n) Eigen evaluates the product coefficient by coefficient instead.
        if (m + k + n < 20) continue;
        Eigen::MatrixXd A(m, k), B(k, n), C0(m, n);
        for (auto* M : {&A, &B, &C0})
          for (Eigen::Index i = 0; i < M->size(); ++i) M->data()[i] = u(rng);
        Eigen::MatrixXd C = C0;
        C.noalias() += alpha * A * B;
        const int peeled = k & ~7, packet_cols = (n / 4) * 4;
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < m; ++i) {
            double c = 0;
            if (j < packet_cols) {
              double d = 0;
              for (int q = 0; q < peeled; q += 2) {
                c = c + A(i, q) * B(q, j);
                d = d + A(i, q + 1) * B(q + 1, j);
              }
              c = c + d;
              for (int q = peeled; q < k; ++q) c = c + A(i, q) * B(q, j);
            } else {
              for (int q = 0; q < k; ++q) c = c + A(i, q) * B(q, j);
            }
            const double ref = c * alpha + C0(i, j);
            ASSERT_EQ(C(i, j), ref) << m << " x " << k << " x " << n << " at (" << i << ", " << j << ")";
          }
        ++checked;
      }
  EXPECT_EQ(checked, 109);
#endif
}

}  // namespace mm
