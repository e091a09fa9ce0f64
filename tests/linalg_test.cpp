#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "linalg/polar.h"
#include "linalg/spd_solver.h"
#include "operators/operators.h"
#include "test_meshes.h"

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

}  // namespace mm
