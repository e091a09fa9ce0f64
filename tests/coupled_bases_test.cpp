// Tests of core/spectral coupled bases and landmark functions (issue 4): landmark validation,
// k chosen on the source, farthest-point landmarks, coupled bases of a same-connectivity pair
// (Γ ≈ I) and of cat → lion with the repo's landmark file (Γ diagonally dominant).
#include <gtest/gtest.h>



#include "io/asset.h"
#include "operators/operators.h"
#include "spectral/coupled_bases.h"
#include "spectral/landmarks.h"
#include "spectral/spectral_basis.h"
#include "io/landmarks_file.h"
#include "test_support.h"

namespace mm::coupled_test {

Mesh load(const std::string& rel) { return test::load_mesh(rel); }

std::vector<LandmarkPair> load_pairs(const std::string& rel) {
  std::vector<LandmarkPair> out;
  const Status s = io::read_landmarks(test::data_path(rel), &out);
  EXPECT_TRUE(s.ok()) << s.message;
  return out;
}

}  // namespace mm::coupled_test

using namespace mm;

TEST(CoupledLandmarks, BadPairsGiveClearErrors) {
  std::vector<LandmarkPair> pairs;
  for (int i = 0; i < 10; ++i) pairs.push_back({i, i});
  EXPECT_TRUE(check_landmarks(pairs, 100, 100, 6).ok());
  Status few = check_landmarks({{1, 1}, {2, 2}}, 100, 100, 6);
  EXPECT_EQ(few.code, StatusCode::InvalidArgument);
  EXPECT_NE(few.message.find("only 2 landmark pairs"), std::string::npos) << few.message;
  pairs[3].source = 100;
  Status range = check_landmarks(pairs, 100, 100, 6);
  EXPECT_EQ(range.code, StatusCode::InvalidArgument);
  EXPECT_NE(range.message.find("pair 3: source vertex 100 is out of range"), std::string::npos) << range.message;
  pairs[3].source = 3;
  pairs[5] = pairs[4];
  EXPECT_NE(check_landmarks(pairs, 100, 100, 6).message.find("pairs 4 and 5 are the same"), std::string::npos);
}

TEST(CoupledLandmarks, SourceRingsMatchNormalizedArea) {
  const Mesh cat = coupled_test::load("pose/cat-reference.ply");
  const Mesh lion = coupled_test::load("pose/lion-reference.ply");
  const auto pairs = coupled_test::load_pairs("landmarks/cat-lion.json");
  ASSERT_GE(pairs.size(), 25u);
  const Eigen::VectorXd mc = mass_diagonal(cat.V, cat.F), ml = mass_diagonal(lion.V, lion.F);
  const LandmarkFunctions lf = landmark_functions(cat.F, mc, lion.F, ml, pairs);
  ASSERT_TRUE(lf.status.ok()) << lf.status.message;
  // Each normalized indicator integrates to 1.
  for (int j = 0; j < lf.reference.cols(); ++j) {
    EXPECT_NEAR(mc.dot(lf.reference.col(j)), 1.0, 1e-12);
    EXPECT_NEAR(ml.dot(lf.source.col(j)), 1.0, 1e-12);
  }
  // The lion (5000 vertices) is coarser than the cat (7207): its rings are mostly ≤ 3.
  int small = 0;
  for (int k : lf.source_rings) small += k <= 3;
  EXPECT_GE(small, static_cast<int>(pairs.size()) / 2);
}

TEST(CoupledLandmarks, FarthestPointLandmarksAreSpread) {
  const Mesh cat = coupled_test::load("pose/cat-reference.ply");
  const std::vector<int> a = farthest_point_landmarks(cat.V, cat.F, 30);
  ASSERT_EQ(a.size(), 30u);
  EXPECT_EQ(a, farthest_point_landmarks(cat.V, cat.F, 30));  // deterministic
  double closest = 1e300;
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < i; ++j) closest = std::min(closest, (cat.V.row(a[i]) - cat.V.row(a[j])).norm());
  EXPECT_GT(closest, 0.02 * bounding_box_diagonal(cat.V));
}

TEST(CoupledBases, CatToLionGammaDiagonallyDominant) {
  const Mesh cat = coupled_test::load("pose/cat-reference.ply");
  const Mesh lion = coupled_test::load("pose/lion-reference.ply");
  const auto pairs = coupled_test::load_pairs("landmarks/cat-lion.json");
  const Eigen::VectorXd mc = mass_diagonal(cat.V, cat.F), ml = mass_diagonal(lion.V, lion.F);
  SpectralBasisOptions so;
  so.k = 20;
  const SpectralBasis bc = spectral_basis(cotan_stiffness(cat.V, cat.F), mc / mc.sum(), so);
  const SpectralBasis bl = spectral_basis(cotan_stiffness(lion.V, lion.F), ml / ml.sum(), so);
  ASSERT_TRUE(bc.status.ok() && bl.status.ok());
  const LandmarkFunctions lf = landmark_functions(cat.F, mc / mc.sum(), lion.F, ml / ml.sum(), pairs);
  const CoupledBases a = coupled_bases(bl.vectors, bl.eigenvalues, ml / ml.sum(), lf.source, bc.vectors,
                                       bc.eigenvalues, mc / mc.sum(), lf.reference);
  ASSERT_TRUE(a.status.ok()) << a.status.message;
  // A-orthonormal.
  const Eigen::MatrixXd G = a.source.transpose() * (ml / ml.sum()).asDiagonal() * a.source;
  EXPECT_LT((G - Eigen::MatrixXd::Identity(10, 10)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(a.energy_final, a.energy_initial);
  EXPECT_GT(a.diagonal_dominance, 1.0) << "Γ not diagonally dominant:\n" << a.gamma;
  // Plain eigenbases are far less compatible.
  Eigen::MatrixXd gamma_plain;
  double dom_plain = 0;
  functional_matrix(bl.vectors.leftCols(10).transpose() * (ml / ml.sum()).asDiagonal() * lf.source,
                    bc.vectors.leftCols(10).transpose() * (mc / mc.sum()).asDiagonal() * lf.reference, 6,
                    &gamma_plain, &dom_plain);
  EXPECT_GT(a.diagonal_dominance, dom_plain);
  std::printf("[ coupled ] cat->lion: Γ dominance %.2f (plain bases %.3f), energy %.4g -> %.4g in %d steps%s\n",
              a.diagonal_dominance, dom_plain, a.energy_initial, a.energy_final, a.iterations,
              a.converged ? "" : " (iteration limit)");
  // Deterministic.
  const CoupledBases b = coupled_bases(bl.vectors, bl.eigenvalues, ml / ml.sum(), lf.source, bc.vectors,
                                       bc.eigenvalues, mc / mc.sum(), lf.reference);
  EXPECT_TRUE(a.X == b.X && a.Y == b.Y);
}
