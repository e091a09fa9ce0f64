// Operators on analytic and real meshes: the sphere's area, W's null space and symmetry,
// the mass lumping's partition of area, normals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "io/asset.h"
#include "operators/operators.h"
#include "test_meshes.h"
#include "test_support.h"

namespace mm {

namespace {
double asymmetry(const SparseMatrix& W) { return (SparseMatrix(W.transpose()) - W).norm(); }
}  // namespace

TEST(MassMatrix, UnitSphereAreaIsFourPi) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(5, &V, &F);
  ASSERT_GE(V.rows(), 10000);
  for (MassType t : {MassType::Voronoi, MassType::Barycentric}) {
    const double area = mass_diagonal(V, F, t).sum();
    EXPECT_NEAR(area, 4 * M_PI, 0.005 * 4 * M_PI);
    EXPECT_NEAR(area, face_areas(V, F).sum(), 1e-9);  // lumping partitions the surface area
  }
  EXPECT_GT(mass_diagonal(V, F).minCoeff(), 0.0);
}

TEST(MassMatrix, ObtuseTrianglesGetNoNegativeArea) {
  Eigen::MatrixXd V(3, 3);
  V << 0, 0, 0, 10, 0, 0, 5, 0.1, 0;  // very obtuse at vertex 2
  Eigen::MatrixXi F(1, 3);
  F << 0, 1, 2;
  const Eigen::VectorXd a = mass_diagonal(V, F);
  EXPECT_GT(a.minCoeff(), 0.0);
  EXPECT_NEAR(a.sum(), 0.5, 1e-12);
  EXPECT_NEAR(a[2], 0.25, 1e-12);  // half the area goes to the obtuse corner
}

TEST(CotanStiffness, AnnihilatesConstantsAndIsSymmetricPsd) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(3, &V, &F);
  const SparseMatrix W = cotan_stiffness(V, F);
  EXPECT_LT((W * Eigen::VectorXd::Ones(V.rows())).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(asymmetry(W), 1e-12);
  // Dirichlet energy of the coordinates: xᵀWx = ½ Σ w (xi - xj)² ≥ 0.
  for (int c = 0; c < 3; ++c) EXPECT_GT(V.col(c).dot(W * V.col(c)), 0.0);
  // Diagonal positive, off-diagonals of a Delaunay-ish sphere negative.
  for (int i = 0; i < W.rows(); ++i) EXPECT_GT(W.coeff(i, i), 0.0);
}

TEST(CotanStiffness, RealMeshesConstantsAndSymmetry) {
  for (const char* file : {"pose/cat-reference.ply", "edit/hand_lowres.ply", "anim/CesiumMan/CesiumMan.glb"}) {
    const io::LoadResult lr = io::load_asset(test::data_path(file));
    ASSERT_TRUE(lr.status.ok()) << lr.status.message;
    const Mesh m = lr.asset.mesh();
    const SparseMatrix W = cotan_stiffness(m.V, m.F);
    const double scale = W.diagonal().cwiseAbs().maxCoeff();
    EXPECT_LT((W * Eigen::VectorXd::Ones(m.V.rows())).cwiseAbs().maxCoeff(), 1e-10 * scale) << file;
    EXPECT_LT(asymmetry(W), 1e-10 * scale) << file;
    EXPECT_TRUE(mass_diagonal(m.V, m.F).allFinite()) << file;
  }
}

// cotan_stiffness assembles each column in place; a setFromTriplets of the four triplets per
// corner (the textbook assembly, summed in triplet order) must give the same matrix bit for bit,
// structural zeros and signs of zero included, on meshes with seams, parts and degenerate faces.
TEST(CotanStiffness, SameBitsAsTheTripletAssembly) {
  auto by_triplets = [](const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
    std::vector<Eigen::Triplet<double>> t;
    for (int f = 0; f < F.rows(); ++f) {
      const int idx[3] = {F(f, 0), F(f, 1), F(f, 2)};
      const Eigen::Vector3d p[3] = {V.row(idx[0]).transpose(), V.row(idx[1]).transpose(), V.row(idx[2]).transpose()};
      const double dbl_area = (p[1] - p[0]).cross(p[2] - p[0]).norm();
      if (!(dbl_area > 0) || !std::isfinite(dbl_area)) continue;
      for (int c = 0; c < 3; ++c) {
        const int i = idx[(c + 1) % 3], j = idx[(c + 2) % 3];
        const double h = 0.5 * (p[(c + 1) % 3] - p[c]).dot(p[(c + 2) % 3] - p[c]) / dbl_area;
        t.emplace_back(i, j, -h);
        t.emplace_back(j, i, -h);
        t.emplace_back(i, i, h);
        t.emplace_back(j, j, h);
      }
    }
    SparseMatrix W(V.rows(), V.rows());
    W.setFromTriplets(t.begin(), t.end());
    return W;
  };
  std::vector<std::pair<Eigen::MatrixXd, Eigen::MatrixXi>> meshes;
  for (const char* file : {"pose/camel_ref.ply", "edit/hand_lowres.ply", "anim/CesiumMan/CesiumMan.glb"}) {
    const io::LoadResult lr = io::load_asset(test::data_path(file));
    ASSERT_TRUE(lr.status.ok()) << file << ": " << lr.status.message;
    meshes.push_back({lr.asset.V_raw, lr.asset.F_raw});
  }
  {  // a zero-area face, a face with a repeated vertex, a vertex only in those, a right angle (cot 0)
    Eigen::MatrixXd V;
    Eigen::MatrixXi F;
    test::grid(5, 4, &V, &F);
    const int n = static_cast<int>(V.rows());
    V.conservativeResize(n + 1, 3);
    V.row(n) = V.row(0);
    F.conservativeResize(F.rows() + 2, 3);
    F.row(F.rows() - 2) << 0, 1, n;
    F.row(F.rows() - 1) << 2, 2, 3;
    meshes.push_back({V, F});
  }
  for (const auto& [V, F] : meshes) {
    const SparseMatrix W = cotan_stiffness(V, F), R = by_triplets(V, F);
    ASSERT_EQ(W.nonZeros(), R.nonZeros());
    ASSERT_TRUE(W.isCompressed());
    EXPECT_TRUE(std::equal(W.outerIndexPtr(), W.outerIndexPtr() + W.cols() + 1, R.outerIndexPtr()));
    EXPECT_TRUE(std::equal(W.innerIndexPtr(), W.innerIndexPtr() + W.nonZeros(), R.innerIndexPtr()));
    EXPECT_EQ(std::memcmp(W.valuePtr(), R.valuePtr(), sizeof(double) * static_cast<size_t>(W.nonZeros())), 0);
  }
  // Faces indexing outside V add nothing (instead of writing out of bounds).
  const auto& [V, F] = meshes.back();
  Eigen::MatrixXi Fbad = F;
  Fbad.conservativeResize(F.rows() + 2, 3);
  Fbad.row(F.rows()) << 0, 1, static_cast<int>(V.rows()) + 5;
  Fbad.row(F.rows() + 1) << -1, 2, 3;
  const SparseMatrix Wg = cotan_stiffness(V, F), Wb = cotan_stiffness(V, Fbad);
  ASSERT_EQ(Wb.nonZeros(), Wg.nonZeros());
  EXPECT_EQ(std::memcmp(Wb.valuePtr(), Wg.valuePtr(), sizeof(double) * static_cast<size_t>(Wg.nonZeros())), 0);
}

TEST(CotanStiffness, LinearFunctionsAreHarmonicInTheInteriorOfAPlane) {
  // On a flat grid, the cotan Laplacian of a linear function vanishes at interior vertices.
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::grid(8, 6, &V, &F);
  const SparseMatrix W = cotan_stiffness(V, F);
  const Eigen::VectorXd f = 2.0 * V.col(0) - 3.0 * V.col(1);
  const Eigen::VectorXd Wf = W * f;
  for (int j = 1; j < 5; ++j)
    for (int i = 1; i < 7; ++i) EXPECT_NEAR(Wf[j * 8 + i], 0.0, 1e-12);
}

TEST(UniformLaplacian, DegreesOnTheDiagonal) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(1, &V, &F);
  const SparseMatrix L = uniform_laplacian(F, static_cast<int>(V.rows()));
  EXPECT_LT((L * Eigen::VectorXd::Ones(V.rows())).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(L.coeff(0, 0), 5.0);  // icosahedron corners keep valence 5
  EXPECT_EQ(L.coeff(12, 12), 6.0);
  EXPECT_LT(asymmetry(L), 1e-15);
}

TEST(Normals, SphereNormalsPointOutward) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  test::icosphere(3, &V, &F);
  const Eigen::MatrixXd N = vertex_normals(V, F);
  for (int i = 0; i < V.rows(); ++i) {
    EXPECT_NEAR(N.row(i).norm(), 1.0, 1e-12);
    EXPECT_GT(N.row(i).dot(V.row(i)), 0.999);
  }
  const Eigen::MatrixXd FN = face_normals(V, F);
  EXPECT_GT((FN.array() * FN.array()).rowwise().sum().minCoeff(), 0.999);
}

}  // namespace mm
