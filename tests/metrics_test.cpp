// Metrics (core/metrics) and the rigid/similarity fit they rest on (core/linalg/rigid_fit.h).
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "linalg/rigid_fit.h"
#include "metrics/edit_metrics.h"
#include "metrics/retarget_metrics.h"
#include "metrics/transfer_metrics.h"
#include "test_meshes.h"
#include "test_support.h"

namespace {

Eigen::Matrix3d metrics_test_rotation() {
  return Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
}

// x ↦ s R x + t, rows.
Eigen::MatrixXd metrics_test_similarity(const Eigen::MatrixXd& V, double s, const Eigen::Matrix3d& R,
                                        const Eigen::RowVector3d& t) {
  Eigen::MatrixXd out = (s * V * R.transpose()).rowwise() + t;
  return out;
}

}  // namespace

TEST(RigidFit, RecoversSimilarityAndRigidMotion) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  mm::test::icosphere(1, &V, &F);
  const Eigen::Matrix3d R = metrics_test_rotation();
  const Eigen::RowVector3d t(0.3, -1.0, 2.0);
  const Eigen::MatrixXd Q = metrics_test_similarity(V, 1.7, R, t);
  mm::RigidFitOptions o;
  o.scale = true;
  const mm::RigidFit sim = mm::fit_rigid(V, Q, o);
  EXPECT_FALSE(sim.degenerate);
  EXPECT_LT((sim.R - R).norm(), 1e-12);
  EXPECT_NEAR(sim.s, 1.7, 1e-12);
  EXPECT_LT((sim.t - t.transpose()).norm(), 1e-12);
  EXPECT_LT(sim.residual2, 1e-20);
  // Rigid fit of a rigid motion: scale stays 1 and the residual vanishes.
  const mm::RigidFit rig = mm::fit_rigid(V, metrics_test_similarity(V, 1.0, R, t));
  EXPECT_EQ(rig.s, 1.0);
  EXPECT_LT((rig.R - R).norm(), 1e-12);
  EXPECT_LT(rig.residual2, 1e-20);
  // Weighted: zero weight on a corrupted point ignores it.
  Eigen::MatrixXd Qbad = metrics_test_similarity(V, 1.0, R, t);
  Qbad.row(0) += Eigen::RowVector3d(5, 5, 5);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(V.rows());
  w[0] = 0;
  const mm::RigidFit wf = mm::fit_rigid(V, Qbad, w);
  EXPECT_LT((wf.R - R).norm(), 1e-12);
  EXPECT_LT((wf.t - t.transpose()).norm(), 1e-12);
  EXPECT_GT(mm::fit_rigid(V, Qbad).residual2, 1.0);
}

TEST(RigidFit, SnapsToAxisRotationAndFlagsDegenerateInput) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  mm::test::icosphere(1, &V, &F);
  // A quarter turn about z plus a small wobble snaps to the exact quarter turn.
  Eigen::Matrix3d Rz;
  Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const Eigen::Matrix3d wobble = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  mm::RigidFitOptions o;
  o.snap_to_axes = true;
  o.scale = true;
  const mm::RigidFit f = mm::fit_rigid(V, metrics_test_similarity(V, 2.0, Rz * wobble, Eigen::RowVector3d::Zero()), o);
  EXPECT_EQ(f.R, Rz);
  EXPECT_NEAR(f.s, 2.0, 1e-2);
  EXPECT_NEAR(std::abs(mm::nearest_axis_rotation(Rz).determinant()), 1.0, 0.0);
  // Collinear points fix no rotation.
  Eigen::MatrixXd line(4, 3);
  for (int i = 0; i < 4; ++i) line.row(i) = Eigen::RowVector3d(i, 2.0 * i, 0);
  o = {};
  o.min_spread = 1e-12;
  const mm::RigidFit d = mm::fit_rigid(line, metrics_test_similarity(line, 1.0, metrics_test_rotation(), {1, 0, 0}), o);
  EXPECT_TRUE(d.degenerate);
  EXPECT_EQ(d.R, Eigen::Matrix3d::Identity());
}

// The per-frame form (rest side computed once) gives fit_rigid's fit on a real mesh: a weighted
// subset of the hand, bent (not rigid), with each option that changes the solve.
TEST(RigidFit, FromRestMatchesTheDirectFitOnABentHand) {
  const mm::Mesh m = mm::test::load_mesh("edit/hand_lowres.ply");
  ASSERT_GT(m.V.rows(), 100);
  const double diag = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();
  std::vector<int> rows;
  for (int i = 0; i < m.V.rows(); i += 3) rows.push_back(i);
  Eigen::VectorXd w(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) w[k] = 0.1 + std::fmod(0.37 * static_cast<double>(k), 1.0);
  w[0] = 0;  // a zero weight counts for nothing in either form
  // A bend about z growing along x, then a similarity.
  Eigen::MatrixXd X = m.V;
  const double x0 = m.V.col(0).minCoeff();
  for (int i = 0; i < X.rows(); ++i) {
    const double a = 0.8 * (m.V(i, 0) - x0) / diag;
    X.row(i) = (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * m.V.row(i).transpose()).transpose();
  }
  X = metrics_test_similarity(X, 1.3, metrics_test_rotation(), {0.2, -0.4, 1.1});
  Eigen::MatrixXd P(rows.size(), 3), Q(rows.size(), 3);
  for (size_t k = 0; k < rows.size(); ++k) P.row(k) = m.V.row(rows[k]), Q.row(k) = X.row(rows[k]);
  for (int variant = 0; variant < 4; ++variant) {
    mm::RigidFitOptions o;
    o.scale = variant == 1 || variant == 3;
    o.snap_to_axes = variant == 2 || variant == 3;
    o.rotation_prior = variant == 0 ? 1e-3 : 0;
    const mm::RigidFit a = mm::fit_rigid(P, Q, w, o);
    const mm::RigidFit b = mm::RigidFitFromRest(m.V, rows, w, o).fit(X);
    SCOPED_TRACE(variant);
    EXPECT_FALSE(b.degenerate);
    EXPECT_LT((a.R - b.R).norm(), 1e-12);
    EXPECT_NEAR(a.s, b.s, 1e-12);
    EXPECT_LT((a.t - b.t).norm(), 1e-12 * diag);
    EXPECT_GT(a.residual2, 1e-6 * a.target_spread2);  // the bend is not rigid: a real residual
    EXPECT_NEAR(a.residual2, b.residual2, 1e-10 * a.target_spread2);
    EXPECT_NEAR(a.target_spread2, b.target_spread2, 1e-12 * a.target_spread2);
  }
  // Nothing to fit: degenerate, not NaN.
  const mm::RigidFit none = mm::RigidFitFromRest(m.V, {}, Eigen::VectorXd(), {}).fit(X);
  EXPECT_TRUE(none.degenerate);
  EXPECT_TRUE(none.R.allFinite() && none.t.allFinite());
}

TEST(EditMetrics, RigidMotionHasNoRigidityErrorAndShearIsDetected) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  mm::test::icosphere(2, &V, &F);
  const Eigen::MatrixXd V1 = metrics_test_similarity(V, 1.3, metrics_test_rotation(), {1, 2, 3});
  // The error is sqrt(residual / spread) with the closed-form Umeyama residual Σ|q̃|² − tr²/Σ|p̃|²,
  // which cancels to ~ε·Σ|q̃|² for an exact similarity: ~√ε ≈ 1e-8 is the floor, not 0.
  EXPECT_LT(mm::local_rigidity_error(V, V1, F).maxCoeff(), 1e-6);
  EXPECT_TRUE(mm::inverted_faces(V, V1, F).empty());
  // Similarity: uniform edge change 0.3, no shear.
  const mm::EdgeDistortion ed = mm::edge_length_distortion(V, V1, F);
  EXPECT_NEAR(ed.mean, 0.3, 1e-9);
  EXPECT_NEAR(ed.max, 0.3, 1e-9);
  EXPECT_LT(mm::gradient_shear(mm::fitted_gradients(V, V1, F)).maxCoeff(), 1e-6);
  // A stretch along x is not a similarity: rigidity error and shear appear.
  Eigen::MatrixXd V2 = V;
  V2.col(0) *= 2.0;
  EXPECT_GT(mm::local_rigidity_error(V, V2, F).mean(), 0.05);
  EXPECT_GT(mm::gradient_shear(mm::fitted_gradients(V, V2, F)).mean(), 0.05);
  // A fold: vertex 0 moved across the opposite edge (a, b) of an incident face f0 (v0 → a + b − v0)
  // flips f0 against the rotation fitted to its neighbourhood; faces not at vertex 0 keep their
  // normals. (A global mirror would not do: each fit is over a centred, nearly flat patch,
  // whose mirror image a rotation reproduces.)
  std::vector<int> incident;
  for (int f = 0; f < F.rows(); ++f)
    if (F(f, 0) == 0 || F(f, 1) == 0 || F(f, 2) == 0) incident.push_back(f);
  ASSERT_GE(incident.size(), 5u);
  const int f0 = incident[0];
  Eigen::MatrixXd V3 = V;
  V3.row(0) = -V.row(0);
  for (int c = 0; c < 3; ++c)
    if (F(f0, c) != 0) V3.row(0) += V.row(F(f0, c));
  const std::vector<int> inv = mm::inverted_faces(V, V3, F);
  EXPECT_NE(std::find(inv.begin(), inv.end(), f0), inv.end()) << "folded face not reported";
  for (int f : inv) EXPECT_NE(std::find(incident.begin(), incident.end(), f), incident.end()) << "face " << f;
  Eigen::VectorXd v(4);
  v << 1, 2, 3, 10;
  EXPECT_DOUBLE_EQ(mm::mean_over(v, {0, 2}), 2.0);
  EXPECT_DOUBLE_EQ(mm::mean_over(v), 4.0);
}

TEST(TransferMetrics, KnownDisplacementGivesExpectedError) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  mm::test::icosphere(2, &V, &F);
  const double diag = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  // Translating every vertex by d: vertex error d / diagonal everywhere, shape unchanged.
  const double d = 0.05;
  const Eigen::MatrixXd A = V.rowwise() + Eigen::RowVector3d(d, 0, 0);
  const mm::TransferMetrics m = mm::transfer_metrics(A, V, F);
  ASSERT_TRUE(m.status.ok());
  EXPECT_NEAR(m.vertex_error_mean, d / diag, 1e-12);
  EXPECT_NEAR(m.vertex_error_max, d / diag, 1e-12);
  EXPECT_NEAR(m.laplacian_change, 0.0, 1e-9);
  EXPECT_NEAR(m.edge_distortion_max, 0.0, 1e-9);
  EXPECT_EQ(m.flipped_faces, 0);
  // Uniform scale 1.1 about the origin: every edge 10 % longer.
  const mm::TransferMetrics s = mm::transfer_metrics(1.1 * V, V, F);
  EXPECT_NEAR(s.edge_distortion_mean, 0.1, 1e-9);
  EXPECT_NEAR(s.laplacian_change, 0.1, 1e-9);
  // Size mismatch is reported.
  EXPECT_FALSE(mm::transfer_metrics(V.topRows(3), V, F).status.ok());
}

TEST(RetargetMetrics, SequenceBoneAndIntersectionMeasures) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  mm::test::icosphere(1, &V, &F);
  // Frame 0 exact, frame 1 every vertex moved by 0.2: mean per frame 0 and 0.2 / scale.
  const std::vector<Eigen::MatrixXd> A = {V, V.rowwise() + Eigen::RowVector3d(0, 0.2, 0)};
  const std::vector<Eigen::MatrixXd> B = {V, V};
  const mm::SequenceError e = mm::sequence_vertex_error(A, B, 2.0);
  ASSERT_EQ(e.per_frame.size(), 2);
  EXPECT_NEAR(e.per_frame[0], 0.0, 1e-15);
  EXPECT_NEAR(e.per_frame[1], 0.1, 1e-12);
  EXPECT_NEAR(e.mean, 0.05, 1e-12);
  EXPECT_NEAR(e.max, 0.1, 1e-12);
  EXPECT_NEAR(e.max_vertex, 0.1, 1e-12);
  // A bone stretched by 50 % in the second frame.
  Eigen::MatrixXd J0(2, 3), J1(2, 3);
  J0 << 0, 0, 0, 0, 1, 0;
  J1 << 0, 0, 0, 0, 1.5, 0;
  const mm::BoneLengthError b = mm::bone_length_error({J0, J1}, {{1, 0}}, Eigen::VectorXd::Ones(1));
  EXPECT_NEAR(b.per_frame[0], 0.0, 1e-15);
  EXPECT_NEAR(b.per_frame[1], 0.5, 1e-12);
  EXPECT_NEAR(b.max, 0.5, 1e-12);
  // A closed convex sphere does not intersect itself; a copy pushed into it does.
  EXPECT_EQ(mm::self_intersection_count(V, F), 0);
  Eigen::MatrixXd V2(2 * V.rows(), 3);
  V2 << V, V.rowwise() + Eigen::RowVector3d(0.5, 0, 0);
  Eigen::MatrixXi F2(2 * F.rows(), 3);
  F2 << F, (F.array() + static_cast<int>(V.rows())).matrix();
  const auto pairs = mm::intersecting_triangle_pairs(V2, F2);
  EXPECT_GT(pairs.size(), 0u);
  EXPECT_EQ(mm::self_intersection_count(V2, F2, pairs), 0);
}
