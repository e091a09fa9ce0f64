// Tests of core/edit (paper 001: implicit Laplacian editing with similarity transformations) and
// core/metrics/edit_metrics. Thresholds come from the measurements printed by
// tests/edit_probe_test.cpp; each test says what it checks and why the bound is what it is.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fstream>
#include <sstream>

#include "app/edit_spec.h"
#include "common/threads.h"
#include "edit/implicit_gradients.h"
#include "edit/laplacian_editor.h"
#include "edit/selection.h"
#include "edit/shear_removal.h"
#include "linalg/polar.h"
#include "linalg/supernodal_cholesky.h"
#include "linalg/spd_solver.h"
#include "operators/operators.h"
#include "edit_test_util.h"
#include "mesh/topology.h"
#include "metrics/edit_metrics.h"

namespace {

using namespace mm;
using namespace mm::edit_test;

bool edit_test_contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

Eigen::MatrixXd edit_test_apply(const HandleTransform& T, const Eigen::MatrixXd& V) {
  Eigen::MatrixXd out(V.rows(), 3);
  for (int i = 0; i < V.rows(); ++i) out.row(i) = T.apply(V.row(i).transpose()).transpose();
  return out;
}

// Eq. 2–4 invariants: M_i = I at rest (on the displaced rest mesh), M_i = R for a rigid motion of
// the whole mesh, and the stencil weights sum to zero (translations do not change M_i).
TEST(Edit, ImplicitGradientsAreExactForAffineMotions) {
  Mesh m = load("edit/bar.ply");
  const auto adj = vertex_adjacency(m.F, m.num_vertices());
  std::vector<int> all(m.num_vertices());
  for (int i = 0; i < m.num_vertices(); ++i) all[i] = i;
  ImplicitGradients g = implicit_gradients(m.V, m.F, adj, all);
  ASSERT_TRUE(g.status.ok()) << g.status.message;
  EXPECT_GT(g.degenerate.size(), 0u);  // the bar's flat sides
  EXPECT_LE(g.max_condition, 2e5);
  const Eigen::Matrix3d A = 1.3 * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  HandleTransform T;
  T.linear = A;
  T.translation = Eigen::Vector3d(3, -1, 2);
  const Eigen::MatrixXd moved = edit_test_apply(T, g.V_displaced);
  double worst_rest = 0, worst_moved = 0, worst_sum = 0;
  for (size_t c = 0; c < g.centers.size(); ++c) {
    worst_rest = std::max(worst_rest, (g.gradient(static_cast<int>(c), g.V_displaced) - Eigen::Matrix3d::Identity()).norm());
    worst_moved = std::max(worst_moved, (g.gradient(static_cast<int>(c), moved) - A).norm());
    Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
    for (int e = g.offsets[c]; e < g.offsets[c + 1]; ++e) sum += g.weights.row(e);
    worst_sum = std::max(worst_sum, sum.norm() * bounding_box_diagonal(m.V));
  }
  EXPECT_LE(worst_rest, 1e-8);
  EXPECT_LE(worst_moved, 1e-8);
  EXPECT_LE(worst_sum, 1e-8);
}

// Sec. 3.3 open-boundary variant: a boundary vertex whose neighbours are collinear cannot be fixed
// by moving itself; a neighbouring interior vertex is displaced instead.
//        A            A on top, B C D on a line, E below: A's neighbours B, C, D are collinear;
//      / | \          C is the only interior vertex.
//     B--C--D
//      \ | /
//        E
TEST(Edit, DegenerateCollinearNeighboursDisplaceInteriorVertex) {
  Eigen::MatrixXd V(5, 3);
  V << 0, 1, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, -1, 0;
  Eigen::MatrixXi F(4, 3);
  F << 0, 1, 2, 0, 2, 3, 1, 4, 2, 2, 4, 3;
  const auto adj = vertex_adjacency(F, 5);
  ImplicitGradients g = implicit_gradients(V, F, adj, {0});
  ASSERT_TRUE(g.status.ok()) << g.status.message;
  EXPECT_EQ(g.degenerate, (std::vector<int>{0}));
  EXPECT_EQ(g.displaced, (std::vector<int>{2}));  // C, not A
  EXPECT_GT(g.V_displaced(2, 2), 0.0);              // along the normal (+z)
  EXPECT_LE(g.max_condition, 2e5);
  EXPECT_LE((g.gradient(0, g.V_displaced) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

// Paper Fig. 2 right: the same similarity on every constrained vertex gives the transformed input
// (max vertex error ≤ 1e-6 of the bbox diagonal). Holds for the stage-1 solve, for drag_positions,
// with gradient constraints, and for the Eq. 10 finalize (which keeps the uniform scale).
TEST(Edit, ConfigurationInvariance) {
  BarCase b = bar_case(true);
  const Eigen::MatrixXd& V = b.mesh.V;
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(1, 2, 3),
                                                        2.0, Eigen::Vector3d(0.1, 0.1, 0.1), 1.7);
  EditRegion region;
  region.handles = {b.region.handles[0], b.region.fixed};
  const Eigen::MatrixXd expected = edit_test_apply(T, V);
  const double tol = 1e-6 * bounding_box_diagonal(V);
  for (double gradient_weight : {0.0, 1.0}) {
    LaplacianEditOptions opt;
    opt.gradient_constraint_weight = gradient_weight;
    LaplacianEditor ed;
    ASSERT_TRUE(ed.precompute(V, b.mesh.F, region, opt).ok());
    EditResult p = ed.drag({T, T});
    ASSERT_TRUE(p.status.ok()) << p.status.message;
    EXPECT_LE((p.V - expected).cwiseAbs().maxCoeff(), tol);
    EditResult f = ed.finalize(FeatureSize::Scale);
    ASSERT_TRUE(f.status.ok()) << f.status.message;
    EXPECT_LE((f.V - expected).cwiseAbs().maxCoeff(), tol);
    EditResult q = ed.drag_positions(expected);
    ASSERT_TRUE(q.status.ok()) << q.status.message;
    EXPECT_LE((q.V - expected).cwiseAbs().maxCoeff(), tol);
  }
}

// Identity handle transforms return the input within 1e-9 (preview, both finalize modes, the
// naive baseline, soft constraints).
TEST(Edit, IdentityHandlesReturnInput) {
  BarCase b = bar_case(true);
  for (int variant = 0; variant < 3; ++variant) {
    LaplacianEditOptions opt;
    if (variant == 1) opt.method = EditMethod::NaiveLaplacian;
    if (variant == 2) opt.soft_constraint_weight = 10;
    LaplacianEditor ed;
    ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region, opt).ok());
    EditResult p = ed.drag({HandleTransform{}});
    ASSERT_TRUE(p.status.ok()) << p.status.message;
    EXPECT_LE((p.V - b.mesh.V).cwiseAbs().maxCoeff(), 1e-9) << "variant " << variant;
    for (FeatureSize mode : {FeatureSize::Keep, FeatureSize::Scale}) {
      EditResult f = ed.finalize(mode);
      ASSERT_TRUE(f.status.ok()) << f.status.message;
      EXPECT_LE((f.V - b.mesh.V).cwiseAbs().maxCoeff(), 1e-9) << "variant " << variant;
    }
  }
}

// Natively the Poisson factor is built on a second thread beside the Eq. 7 system
// (common/threads.h): one thread and two give the same edit bit for bit.
TEST(Edit, OneAndTwoThreadsGiveTheSameEdit) {
  // Subdivided twice (5.6k vertices): enough unknowns (≥ 2000) for the two-thread assembly of
  // the Eq. 7 system.
  BarCase b = bar_case(true, "edit/bar.ply", 2);
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.2, 0.1, 0), Eigen::Vector3d::UnitZ(), 0.7,
                                                        b.mesh.V.colwise().mean().transpose());
  Eigen::MatrixXd dragged[2], finalized[2];
  for (int threads : {1, 2}) {
    set_max_threads(threads);
    LaplacianEditor ed;
    ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region).ok());
    EditResult d = ed.drag({T});
    ASSERT_TRUE(d.status.ok()) << d.status.message;
    EditResult f = ed.finalize();
    ASSERT_TRUE(f.status.ok()) << f.status.message;
    dragged[threads - 1] = d.V;
    finalized[threads - 1] = f.V;
  }
  set_max_threads(0);
  EXPECT_TRUE(dragged[0] == dragged[1]);
  EXPECT_TRUE(finalized[0] == finalized[1]);
  EXPECT_GT((finalized[0] - b.mesh.V).cwiseAbs().maxCoeff(), 0.05);  // the edit moved the bar
}

// The per-handle response basis (drag) and the three back-substitutions (drag_positions, or
// drag with handle_basis = false) are the same linear solve.
TEST(Edit, HandleBasisMatchesBackSubstitution) {
  BarCase b = bar_case(true);
  LaplacianEditor with_basis, without;
  LaplacianEditOptions opt;
  ASSERT_TRUE(with_basis.precompute(b.mesh.V, b.mesh.F, b.region, opt).ok());
  opt.handle_basis = false;
  ASSERT_TRUE(without.precompute(b.mesh.V, b.mesh.F, b.region, opt).ok());
  EditResult a = with_basis.drag({b.transform});
  EditResult c = without.drag({b.transform});
  Eigen::MatrixXd targets = b.mesh.V;
  for (int v : b.region.handles[0]) targets.row(v) = b.transform.apply(b.mesh.V.row(v).transpose()).transpose();
  EditResult d = with_basis.drag_positions(targets);
  ASSERT_TRUE(a.status.ok() && c.status.ok() && d.status.ok());
  const double tol = 1e-9 * bounding_box_diagonal(b.mesh.V);
  EXPECT_LE((a.V - c.V).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((a.V - d.V).cwiseAbs().maxCoeff(), tol);
}

struct EditTestComparison {
  Eigen::VectorXd ours, naive, ideal;  // per-vertex local rigidity error after finalize / reference
  size_t inverted_ours = 0, inverted_naive = 0;
  double shear_before = 0, shear_after = 0;
};

EditTestComparison edit_test_compare(const BarCase& b, bool bend) {
  EditTestComparison c;
  LaplacianEditor ed;
  EXPECT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region).ok());
  EditResult p = ed.drag({b.transform});
  EXPECT_TRUE(p.status.ok()) << p.status.message;
  EditResult f = ed.finalize();
  EXPECT_TRUE(f.status.ok()) << f.status.message;
  LaplacianEditOptions nopt;
  nopt.method = EditMethod::NaiveLaplacian;
  LaplacianEditResult nv = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, nopt);
  EXPECT_TRUE(nv.status.ok()) << nv.status.message;
  c.ours = local_rigidity_error(b.mesh.V, f.V, b.mesh.F);
  c.naive = local_rigidity_error(b.mesh.V, nv.V, b.mesh.F);
  c.ideal = local_rigidity_error(b.mesh.V, ideal_bar_deformation(b.mesh.V, bend), b.mesh.F);
  c.inverted_ours = inverted_faces(b.mesh.V, f.V, b.mesh.F).size();
  c.inverted_naive = inverted_faces(b.mesh.V, nv.V, b.mesh.F).size();
  c.shear_before = gradient_shear(ed.gradients()).mean();
  c.shear_after = gradient_shear(fitted_gradients(b.mesh.V, f.V, b.mesh.F)).mean();
  std::cout << "[ rigidity error mean / p90 / max ] ours " << c.ours.mean() << " / " << quantile(c.ours, 0.9) << " / "
            << c.ours.maxCoeff() << ", naive " << c.naive.mean() << " / " << quantile(c.naive, 0.9) << " / "
            << c.naive.maxCoeff() << ", ideal " << c.ideal.mean() << "; inverted ours " << c.inverted_ours
            << ", naive " << c.inverted_naive << "\n";
  ::testing::Test::RecordProperty("ours_mean", std::to_string(c.ours.mean()));
  ::testing::Test::RecordProperty("naive_mean", std::to_string(c.naive.mean()));
  ::testing::Test::RecordProperty("ideal_mean", std::to_string(c.ideal.mean()));
  return c;
}

// Bar (data/edit/bar.ply) bent 90° into a quarter circle by one end, other end fixed. Measured:
// ours mean 0.061 / p90 0.11 / max 0.27, naive 0.196 / 0.35 / 0.77 with 4 inverted faces; the
// ideal bend of this short, thick bar (±21% strain at its surface) has 0.05 itself.
TEST(Edit, BarBend90BeatsNaiveLaplacian) {
  const EditTestComparison c = edit_test_compare(bar_case(true), true);
  EXPECT_LE(c.ours.mean() * 3.0, c.naive.mean());  // the issue's bound
  EXPECT_LE(quantile(c.ours, 0.9) * 3.0, quantile(c.naive, 0.9));
  EXPECT_LE(c.ours.mean(), 1.5 * c.ideal.mean());
  EXPECT_EQ(c.inverted_ours, 0u);
  EXPECT_GT(c.inverted_naive, 0u);
  EXPECT_LT(c.shear_after, c.shear_before);  // Sec. 4: shear removal
}

// The same bend of a slender cylinder (length 20 radii): measured ours 0.026, naive 0.21 (8×).
TEST(Edit, SlenderCylinderBend90BeatsNaiveLaplacian) {
  const EditTestComparison c = edit_test_compare(bar_case_of(slender_cylinder(), true), true);
  EXPECT_LE(c.ours.mean() * 5.0, c.naive.mean());
  EXPECT_LE(c.ours.mean(), 2.0 * c.ideal.mean() + 0.01);
  EXPECT_EQ(c.inverted_ours, 0u);
  EXPECT_GT(c.inverted_naive, 0u);
}

// Twist by 150° about the long axis. The issue asks for a 3× lower mean rigidity error than naive
// Laplacian editing; that is not reachable by any deformation that spreads the twist: the ideal
// uniform twist (rigid cross-sections) has a mean error close to naive's, because naive keeps most
// 1-rings untouched and collapses the bar next to the handle (candy wrapper: the slender
// cylinder's radius drops to 0.36 r there), which a
// mean rewards. What we assert instead: no inverted face (naive has them), a much lower worst
// case and 90th percentile, and a mean within a small factor of the ideal twist's.
TEST(Edit, BarTwist150AvoidsCandyWrapper) {
  const EditTestComparison c = edit_test_compare(bar_case(false), false);
  EXPECT_LE(c.ours.maxCoeff() * 1.5, c.naive.maxCoeff());
  EXPECT_LE(quantile(c.ours, 0.9) * 1.3, quantile(c.naive, 0.9));
  EXPECT_LE(c.ours.mean(), 1.5 * c.ideal.mean());
  EXPECT_EQ(c.inverted_ours, 0u);
  EXPECT_GT(c.inverted_naive, 0u);
  EXPECT_LT(c.shear_after, c.shear_before);
}

TEST(Edit, SlenderCylinderTwist150) {
  const EditTestComparison c = edit_test_compare(bar_case_of(slender_cylinder(), false), false);
  EXPECT_LE(c.ours.maxCoeff() * 1.5, c.naive.maxCoeff());
  EXPECT_LE(c.ours.mean(), 1.5 * c.ideal.mean());
  EXPECT_EQ(c.inverted_ours, 0u);
}

// Translation-only drag of the hand of a character: the arm's details must rotate with it.
// Detail angle = |δ0|-weighted mean angle between D(ṽ_i) (rest weights) and the deformed normal
// over the free arm vertices; 0.9° at rest. Measured at a lift of 15% of the height: ours 8.9°,
// naive 18.2°.
TEST(Edit, LimbTranslationRotatesDetails) {
  LimbCase c = limb_case();
  const HandleTransform T;
  HandleTransform lift;
  lift.translation = Eigen::Vector3d(0, 0.15 * c.height, 0);
  LaplacianEditResult ours = laplacian_edit(c.mesh.V, c.mesh.F, c.region, {lift});
  ASSERT_TRUE(ours.status.ok()) << ours.status.message;
  LaplacianEditOptions nopt;
  nopt.method = EditMethod::NaiveLaplacian;
  LaplacianEditResult naive = laplacian_edit(c.mesh.V, c.mesh.F, c.region, {lift}, nopt);
  ASSERT_TRUE(naive.status.ok()) << naive.status.message;
  const DetailPreservation d_ours = detail_preservation(c.mesh.V, ours.V, c.mesh.F, c.free);
  const DetailPreservation d_naive = detail_preservation(c.mesh.V, naive.V, c.mesh.F, c.free);
  EXPECT_LE(d_ours.rest_mean_angle_deg, 2.0);
  EXPECT_LE(d_ours.mean_angle_deg, 10.0);
  EXPECT_GE(d_naive.mean_angle_deg, 1.5 * d_ours.mean_angle_deg);
  EXPECT_TRUE(inverted_faces(c.mesh.V, ours.V, c.mesh.F).empty());
  std::cout << "[ limb detail angle ] ours " << d_ours.mean_angle_deg << "°, naive " << d_naive.mean_angle_deg
            << "°, rest " << d_ours.rest_mean_angle_deg << "°\n";
  (void)T;
}

// Paper Fig. 3: a planar irregular patch (every vertex degenerate), boundary fixed, the central
// disk lifted and tilted. Pull-back bound (Sec. 3.3): after ṽ = M(v − v') + ṽ', a displaced vertex
// lies within 0.01·h (mean) and 0.05·h (max) of the least-squares plane of its deformed 1-ring
// (h = mean edge length; measured 0.0005·h / 0.010·h), i.e. far below the 0.2·h offset it would
// keep without the pull-back. Cotangent weights leave a smaller finalize error than uniform ones
// (paper Fig. 3 d/e; measured 0.007·h vs 0.027·h), and s_disp = 0.2 vs 10 changes the finalized
// shape little (Fig. 6).
TEST(Edit, DegeneratePlanarPatchPullBack) {
  Mesh m = planar_patch(20);
  EditRegion region;
  std::vector<int> center, boundary;
  for (int i = 0; i < m.num_vertices(); ++i) {
    if ((m.V.row(i) - Eigen::RowVector3d(0.5, 0.5, 0)).norm() < 0.12) center.push_back(i);
    const double x = m.V(i, 0), y = m.V(i, 1);
    if (x == 0 || y == 0 || x == 1 || y == 1) boundary.push_back(i);
  }
  region.handles = {center};
  region.fixed = boundary;
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0, 0, 0.3), Eigen::Vector3d(1, 0, 0), 0.5,
                                                        Eigen::Vector3d(0.5, 0.5, 0));
  const auto adj = vertex_adjacency(m.F, m.num_vertices());
  std::vector<char> constrained(m.num_vertices(), 0);
  for (int v : center) constrained[v] = 1;
  for (int v : boundary) constrained[v] = 1;
  Eigen::MatrixXd finals[3];
  double final_error[3];
  int run = 0;
  for (auto [weights, sdisp] : {std::pair{LaplacianWeights::Cotangent, 0.2}, std::pair{LaplacianWeights::Uniform, 0.2},
                                std::pair{LaplacianWeights::Cotangent, 10.0}}) {
    LaplacianEditOptions opt;
    opt.weights = weights;
    opt.displacement_scale = sdisp;
    LaplacianEditor ed;
    Status s = ed.precompute(m.V, m.F, region, opt);
    ASSERT_TRUE(s.ok()) << s.message;
    EXPECT_GT(ed.stats().degenerate_vertices, 100);
    EXPECT_GT(ed.stats().displaced_vertices, 100);
    EXPECT_GE(ed.stats().widened_stencils, 1);  // a corner with a single triangle
    EditResult p = ed.drag({T});
    ASSERT_TRUE(p.status.ok()) << p.status.message;
    EditResult f = ed.finalize();
    ASSERT_TRUE(f.status.ok()) << f.status.message;
    const double h = ed.stats().mean_edge_length;
    double mean_p = 0, max_p = 0, mean_f = 0;
    int count = 0;
    for (int v : ed.displaced_vertices()) {
      if (constrained[v]) continue;
      const double dp = plane_distance(p.V, v, adj[v]) / h;
      mean_p += dp;
      max_p = std::max(max_p, dp);
      mean_f += plane_distance(f.V, v, adj[v]) / h;
      ++count;
    }
    ASSERT_GT(count, 0);
    mean_p /= count;
    mean_f /= count;
    if (sdisp == 0.2) {
      EXPECT_LE(mean_p, 0.01) << "run " << run;
      EXPECT_LE(max_p, 0.05) << "run " << run;
    }
    finals[run] = f.V;
    final_error[run] = mean_f;
    ++run;
  }
  EXPECT_LT(final_error[0], final_error[1]);  // cotangent better than uniform
  EXPECT_LE((finals[0] - finals[2]).cwiseAbs().maxCoeff(), 0.02 * bounding_box_diagonal(m.V));
}

// Soft constraints with a large weight converge to the hard (eliminated) constraints.
TEST(Edit, SoftConstraintsApproachHardOnes) {
  BarCase b = bar_case(true);
  LaplacianEditResult hard = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform});
  LaplacianEditOptions opt;
  opt.soft_constraint_weight = 1e6;
  LaplacianEditResult soft = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, opt);
  ASSERT_TRUE(hard.status.ok() && soft.status.ok()) << soft.status.message;
  const double diag = bounding_box_diagonal(b.mesh.V);
  EXPECT_LE((hard.preview - soft.preview).cwiseAbs().maxCoeff(), 1e-3 * diag);
  EXPECT_LE((hard.V - soft.V).cwiseAbs().maxCoeff(), 1e-3 * diag);
  opt.soft_constraint_weight = 1e-2;  // weak: the handle lags behind its target
  LaplacianEditResult weak = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform}, opt);
  ASSERT_TRUE(weak.status.ok());
  EXPECT_GT((hard.preview - weak.preview).cwiseAbs().maxCoeff(), 1e-2 * diag);
}

// Feature scaling (Eq. 10) follows a uniform scale of the handles; Eq. 9 keeps feature sizes.
TEST(Edit, ScaleFeaturesFollowsHandleScale) {
  BarCase b = bar_case(true);
  const Eigen::Vector3d c = b.mesh.V.colwise().mean().transpose();
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0, c, 1.5);
  EditRegion region;
  region.handles = {b.region.handles[0], b.region.fixed};
  LaplacianEditor ed;
  ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, region).ok());
  ASSERT_TRUE(ed.drag({T, T}).status.ok());
  EditResult keep = ed.finalize(FeatureSize::Keep), scale = ed.finalize(FeatureSize::Scale);
  ASSERT_TRUE(keep.status.ok() && scale.status.ok());
  const Eigen::MatrixXd expected = edit_test_apply(T, b.mesh.V);
  EXPECT_LE((scale.V - expected).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_GT((keep.V - expected).cwiseAbs().maxCoeff(), 1e-3);  // details keep their rest size
}

TEST(Edit, BadInputsGiveClearStatus) {
  BarCase b = bar_case(true);
  const Eigen::MatrixXd& V = b.mesh.V;
  const Eigen::MatrixXi& F = b.mesh.F;
  auto precompute_error = [&](const EditRegion& r, const LaplacianEditOptions& o = {}) {
    LaplacianEditor ed;
    Status s = ed.precompute(V, F, r, o);
    EXPECT_FALSE(ed.ready());
    return s;
  };
  EditRegion r;
  Status s = precompute_error(r);
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  EXPECT_TRUE(edit_test_contains(s.message, "no handle")) << s.message;
  r.handles = {{}};
  s = precompute_error(r);
  EXPECT_TRUE(edit_test_contains(s.message, "handle 0 is empty")) << s.message;
  r.handles = {{0, 1, static_cast<int>(V.rows())}};
  s = precompute_error(r);
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  EXPECT_TRUE(edit_test_contains(s.message, "out of range")) << s.message;
  r.handles = {{0, 1}, {1, 2}};
  s = precompute_error(r);
  EXPECT_TRUE(edit_test_contains(s.message, "must not overlap")) << s.message;
  r.handles = {{0, 1}};
  r.fixed = {1};
  s = precompute_error(r);
  EXPECT_TRUE(edit_test_contains(s.message, "both fixed and in handle")) << s.message;
  r.fixed = {};
  r.roi = {0, 1};
  s = precompute_error(r);
  EXPECT_TRUE(edit_test_contains(s.message, "no free vertex")) << s.message;
  r.roi = {-3};
  s = precompute_error(r);
  EXPECT_TRUE(edit_test_contains(s.message, "ROI vertex index -3")) << s.message;
  LaplacianEditOptions bad;
  bad.coherence_weight = -1;
  s = precompute_error(b.region, bad);
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);

  // Non-manifold ROI: a fin (two extra triangles) on an edge in the middle of the bar → an edge
  // with 4 faces.
  {
    const int f0 = static_cast<int>(F.rows()) / 2;
    Eigen::MatrixXd V2(V.rows() + 2, 3);
    V2 << V, V.row(F(f0, 0)) + Eigen::RowVector3d(0, 0, 0.1), V.row(F(f0, 1)) + Eigen::RowVector3d(0, 0.1, 0);
    Eigen::MatrixXi F2(F.rows() + 2, 3);
    F2 << F, F(f0, 0), F(f0, 1), static_cast<int>(V.rows()), F(f0, 1), F(f0, 0), static_cast<int>(V.rows()) + 1;
    LaplacianEditor ed;
    s = ed.precompute(V2, F2, b.region);
    EXPECT_EQ(s.code, StatusCode::InvalidMesh);
    EXPECT_TRUE(edit_test_contains(s.message, "non-manifold")) << s.message;
  }
  // NaN in the mesh.
  {
    Eigen::MatrixXd V2 = V;
    V2(5, 1) = std::numeric_limits<double>::quiet_NaN();
    LaplacianEditor ed;
    EXPECT_EQ(ed.precompute(V2, F, b.region).code, StatusCode::InvalidMesh);
  }
  // Transforms.
  LaplacianEditor ed;
  EXPECT_EQ(ed.drag({HandleTransform{}}).status.code, StatusCode::InvalidArgument);  // before precompute
  ASSERT_TRUE(ed.precompute(V, F, b.region).ok());
  EXPECT_EQ(ed.finalize().status.code, StatusCode::InvalidArgument);  // before a drag
  HandleTransform nan_t;
  nan_t.translation[1] = std::numeric_limits<double>::quiet_NaN();
  EditResult e = ed.drag({nan_t});
  EXPECT_EQ(e.status.code, StatusCode::InvalidArgument);
  EXPECT_TRUE(edit_test_contains(e.status.message, "non-finite")) << e.status.message;
  e = ed.drag({HandleTransform{}, HandleTransform{}});
  EXPECT_TRUE(edit_test_contains(e.status.message, "2 handle transforms for 1 handles")) << e.status.message;
  Eigen::MatrixXd targets = V;
  targets(b.region.handles[0][0], 0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ed.drag_positions(targets).status.code, StatusCode::InvalidArgument);
  EXPECT_EQ(ed.drag_positions(Eigen::MatrixXd::Zero(3, 3)).status.code, StatusCode::InvalidArgument);
}

TEST(Edit, PrecomputeCanBeCancelled) {
  BarCase b = bar_case(true);
  int calls = 0;
  Progress progress([&](const std::string&, double) { return ++calls < 3; });
  LaplacianEditor ed;
  Status s = ed.precompute(b.mesh.V, b.mesh.F, b.region, {}, progress);
  EXPECT_EQ(s.code, StatusCode::Cancelled);
  EXPECT_FALSE(ed.ready());
  // Progress never goes back (the factor's analysis used to report 0.5 and 1 of its range before
  // the numeric phase started again from 0) and reaches 1 on success.
  test::ForwardProgress watch;
  ASSERT_TRUE(ed.precompute(b.mesh.V, b.mesh.F, b.region, {}, watch.sink()).ok());
  EXPECT_TRUE(watch.backwards.empty()) << watch.backwards.front();
  EXPECT_DOUBLE_EQ(watch.last, 1.0);
}

// ROI defaults to the handle's component; vertices outside an explicit ROI do not move.
TEST(Edit, RegionOfInterest) {
  BarCase b = bar_case(true);
  const int ax = long_axis(b.mesh.V);
  EditRegion region = b.region;
  region.roi = slab(b.mesh.V, ax, 0.6, true);  // the handle half of the bar
  LaplacianEditResult r = laplacian_edit(b.mesh.V, b.mesh.F, region, {b.transform});
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  std::vector<char> in_roi(b.mesh.num_vertices(), 0);
  for (int v : region.roi) in_roi[v] = 1;
  for (int v = 0; v < b.mesh.num_vertices(); ++v)
    if (!in_roi[v]) EXPECT_EQ((r.V.row(v) - b.mesh.V.row(v)).norm(), 0.0);
  EXPECT_GT((r.V - b.mesh.V).rowwise().norm().maxCoeff(), 0.1);
}

TEST(Edit, SelectionSelectors) {
  Mesh m = planar_patch(10);  // 11×11 grid on [0,1]², spacing 0.1
  VertexSelection sel;
  sel.indices = {3, 1};
  SelectionResult r = select_vertices(m.V, m.F, sel);
  ASSERT_TRUE(r.status.ok());
  EXPECT_EQ(r.vertices, (std::vector<int>{1, 3}));
  sel = {};
  sel.boxes.push_back({Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(2, 0.01, 1)});  // the y = 0 row
  r = select_vertices(m.V, m.F, sel);
  EXPECT_EQ(r.vertices.size(), 11u);
  sel = {};
  sel.spheres.push_back({Eigen::Vector3d(0, 0, 0), 0.01});
  r = select_vertices(m.V, m.F, sel);
  EXPECT_EQ(r.vertices, (std::vector<int>{0}));
  sel = {};
  sel.rings.push_back({60, 1});  // interior vertex: itself + its neighbours
  r = select_vertices(m.V, m.F, sel);
  const auto adj = vertex_adjacency(m.F, m.num_vertices());
  EXPECT_EQ(r.vertices.size(), adj[60].size() + 1);
  sel = {};
  sel.disks.push_back({60, 0.25});
  r = select_vertices(m.V, m.F, sel);
  for (int v : r.vertices) EXPECT_LE((m.V.row(v) - m.V.row(60)).norm(), 0.25 + 1e-12);
  EXPECT_GT(r.vertices.size(), adj[60].size() + 1);
  sel.disks.push_back({500, 1.0});
  r = select_vertices(m.V, m.F, sel);
  EXPECT_EQ(r.status.code, StatusCode::InvalidArgument);
  EXPECT_TRUE(edit_test_contains(r.status.message, "500")) << r.status.message;
  sel = {};
  sel.spheres.push_back({Eigen::Vector3d(0, 0, 0), -1});
  EXPECT_EQ(select_vertices(m.V, m.F, sel).status.code, StatusCode::InvalidArgument);
}

// Metric invariants: a similarity motion has zero rigidity error, shear, inversion; edge distortion
// equals |s − 1|; a non-uniform stretch shows up in all of them.
TEST(Edit, MetricInvariants) {
  Mesh m = load("edit/decimated-knight.ply");
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0, 1, 1), 1.0,
                                                        Eigen::Vector3d::Zero(), 2.0);
  const Eigen::MatrixXd V1 = edit_test_apply(T, m.V);
  EXPECT_LE(local_rigidity_error(m.V, V1, m.F).maxCoeff(), 1e-6);
  EXPECT_LE(gradient_shear(fitted_gradients(m.V, V1, m.F)).maxCoeff(), 1e-6);
  EXPECT_TRUE(inverted_faces(m.V, V1, m.F).empty());
  const EdgeDistortion e = edge_length_distortion(m.V, V1, m.F);
  EXPECT_NEAR(e.mean, 1.0, 1e-9);
  EXPECT_NEAR(e.max, 1.0, 1e-9);
  const DetailPreservation d = detail_preservation(m.V, V1, m.F);
  EXPECT_NEAR(d.mean_angle_deg, d.rest_mean_angle_deg, 1e-6);
  Eigen::MatrixXd S = m.V;
  S.col(0) *= 2.0;
  EXPECT_GT(local_rigidity_error(m.V, S, m.F).mean(), 0.05);
  EXPECT_GT(gradient_shear(fitted_gradients(m.V, S, m.F)).mean(), 0.05);
  // A fold: one interior vertex of a planar patch pushed across its neighbours flips faces around it.
  Mesh p = planar_patch(10);
  Eigen::MatrixXd folded = p.V;
  folded.row(60) += Eigen::RowVector3d(0.25, 0.0, 0.0);
  const std::vector<int> inv = inverted_faces(p.V, folded, p.F);
  EXPECT_FALSE(inv.empty());
  for (int f : inv) EXPECT_TRUE(p.F(f, 0) == 60 || p.F(f, 1) == 60 || p.F(f, 2) == 60);
}

std::string edit_test_read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The example specs of data/specs parse on their meshes and run end to end.
TEST(Edit, ExampleSpecsRun) {
  const std::pair<const char*, const char*> examples[] = {{"specs/bar_twist.json", "edit/bar.ply"},
                                                          {"specs/bar_bend.json", "edit/bar.ply"},
                                                          {"specs/woman_arm.json", "anim/human_woman.ply"},
                                                          {"specs/armadillo_wave.json", "edit/armadillo.ply"}};
  for (const auto& [spec_file, mesh_file] : examples) {
    if (std::string(mesh_file) == "edit/armadillo.ply") continue;  // 14.6k vertices: covered by the CLI and bench
    Mesh m = load(mesh_file);
    EditSpecResult r = parse_edit_spec(edit_test_read(test::data_path(spec_file)), m.V, m.F);
    ASSERT_TRUE(r.status.ok()) << spec_file << ": " << r.status.message;
    ASSERT_EQ(r.spec.region.handles.size(), r.spec.transforms.size());
    LaplacianEditResult e = laplacian_edit(m.V, m.F, r.spec.region, r.spec.transforms, r.spec.options, r.spec.features);
    ASSERT_TRUE(e.status.ok()) << spec_file << ": " << e.status.message;
    EXPECT_TRUE(inverted_faces(m.V, e.V, m.F).empty()) << spec_file;
  }
}

TEST(Edit, SpecParsing) {
  BarCase b = bar_case(false);
  const Eigen::MatrixXd& V = b.mesh.V;
  const Eigen::MatrixXi& F = b.mesh.F;
  // Selections, units, transforms, options.
  EditSpecResult r = parse_edit_spec(R"({
      "roi": {"slabs": [{"axis": "long", "from": 0.0, "to": 1.0}]},
      "fixed": [0, 1, 2],
      "handles": [{"select": {"spheres": [{"vertex": 100, "radius_rel": 0.05}], "rings": [{"vertex": 100, "k": 1}]},
                   "translate_rel": [0.1, 0, 0], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "pivot": [0, 0, 0],
                   "scale": 2}],
      "features": "scale",
      "options": {"method": "naive", "weights": "uniform", "coherence_rings": 1, "soft_constraint_weight": 3}})",
                                     V, F);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_EQ(r.spec.region.roi.size(), static_cast<size_t>(V.rows()));
  EXPECT_EQ(r.spec.region.fixed, (std::vector<int>{0, 1, 2}));
  EXPECT_GE(r.spec.region.handles[0].size(), 1u);
  EXPECT_EQ(r.spec.features, FeatureSize::Scale);
  EXPECT_EQ(r.spec.options.method, EditMethod::NaiveLaplacian);
  EXPECT_EQ(r.spec.options.weights, LaplacianWeights::Uniform);
  EXPECT_EQ(r.spec.options.coherence_rings, 1);
  EXPECT_EQ(r.spec.options.soft_constraint_weight, 3);
  const HandleTransform& t = r.spec.transforms[0];
  const Eigen::Vector3d x(1, 0, 0);
  EXPECT_LE((t.apply(x) - Eigen::Vector3d(0.1 * bounding_box_diagonal(V), 2, 0)).norm(), 1e-12);
  // A three.js matrix (column-major) for drags.
  HandleTransformsResult tr = parse_handle_transforms(
      R"([{"matrix": [0,1,0,0, -1,0,0,0, 0,0,1,0, 5,6,7,1]}])", V, b.region);
  ASSERT_TRUE(tr.status.ok()) << tr.status.message;
  EXPECT_LE((tr.transforms[0].apply(x) - Eigen::Vector3d(5, 7, 7)).norm(), 1e-12);
  // Errors.
  auto code = [&](const std::string& json) { return parse_edit_spec(json, V, F).status; };
  EXPECT_EQ(code("{").code, StatusCode::ParseError);
  EXPECT_EQ(code("[]").code, StatusCode::ParseError);
  Status s = code(R"({"handles": [{"select": [1], "rotat": {}}]})");
  EXPECT_EQ(s.code, StatusCode::ParseError);
  EXPECT_TRUE(edit_test_contains(s.message, "rotat")) << s.message;
  s = code(R"({"handles": []})");
  EXPECT_TRUE(edit_test_contains(s.message, "non-empty")) << s.message;
  s = code(R"({"handles": [{"select": {"boxes": [{"min": [9, 9, 9], "max": [10, 10, 10]}]}}]})");
  EXPECT_TRUE(edit_test_contains(s.message, "selects no vertex")) << s.message;
  s = code(R"({"handles": [{"select": [1], "scale": "big"}]})");
  EXPECT_EQ(s.code, StatusCode::ParseError);
  s = code(R"({"handles": [{"select": [99999]}]})");
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  EXPECT_TRUE(edit_test_contains(s.message, "99999")) << s.message;
  s = code(R"({"handles": [{"select": [1], "scale": -1}]})");
  EXPECT_EQ(s.code, StatusCode::InvalidArgument);
  s = code(R"({"handles": [{"select": [1]}], "options": {"weights": "cot"}})");
  EXPECT_EQ(s.code, StatusCode::ParseError);
  EXPECT_EQ(parse_handle_transforms("[{}, {}]", V, b.region).status.code, StatusCode::InvalidArgument);
  EXPECT_EQ(parse_handle_transforms(R"([{"matrix": [1]}])", V, b.region).status.code, StatusCode::ParseError);
}

// The supernodal factorization solves the same systems as the simplicial LDLT: a 2-ring
// (cotangent LᵀL + identity) matrix of a real mesh, several right-hand sides; and reports
// non-SPD matrices.
TEST(Edit, SupernodalCholeskyMatchesSimplicial) {
  Mesh m = load("edit/decimated-knight.ply");
  const SparseMatrix W = cotan_stiffness(m.V, m.F);
  SparseMatrix I(W.rows(), W.cols());
  I.setIdentity();
  const SparseMatrix A = SparseMatrix(W.transpose()) * W + 1e-2 * I;
  SupernodalCholesky sn;
  ASSERT_TRUE(sn.factor(A).ok());
  EXPECT_GT(sn.supernodes(), 0);
  SpdSolver ref;
  ASSERT_TRUE(ref.factor(A).ok());
  Eigen::MatrixXd B(W.rows(), 5);
  for (int i = 0; i < B.rows(); ++i)
    for (int c = 0; c < 5; ++c) B(i, c) = std::sin(1.0 + i * 0.37 + c * 1.3);
  Eigen::MatrixXd X, Xr;
  ASSERT_TRUE(sn.solve(B, &X).ok());
  ASSERT_TRUE(ref.solve(B, &Xr).ok());
  EXPECT_LE((X - Xr).cwiseAbs().maxCoeff(), 1e-8 * Xr.cwiseAbs().maxCoeff());
  EXPECT_LE((A * X - B).cwiseAbs().maxCoeff(), 1e-8 * B.cwiseAbs().maxCoeff());
  // Two threads (the tree's subtrees shared out, forced on this small system): the same factor
  // bit for bit (natively; the wasm build has one thread and takes the sequential path).
  SupernodalCholesky sn2;
  sn2.parallel_min_flops = 0;
  set_max_threads(2);
  ASSERT_TRUE(sn2.factor(A).ok());
  Eigen::MatrixXd X2, X3;
  ASSERT_TRUE(sn2.solve(B, &X2).ok());  // the solve on the same split (subtree logs replayed)
  EXPECT_TRUE(X2 == X);
  set_max_threads(1);
  ASSERT_TRUE(sn2.solve(B, &X3).ok());  // the sequential solve of the same factor
  EXPECT_TRUE(X3 == X);
  set_max_threads(2);
  // Indefinite: flip one diagonal entry far negative (on either path).
  SparseMatrix Bad = A;
  Bad.coeffRef(7, 7) = -1.0;
  EXPECT_EQ(sn2.factor(Bad).code, StatusCode::FactorizationFailed);
  set_max_threads(0);
  EXPECT_EQ(sn.factor(Bad).code, StatusCode::FactorizationFailed);
  // Singular: the pure Laplacian has constants in its null space.
  EXPECT_EQ(sn.factor(SparseMatrix(W.transpose()) * W).code, StatusCode::FactorizationFailed);
}

// The fast rotation extraction agrees with the SVD-based polar decomposition, including the
// fallback cases (near-singular, reflected).
TEST(Edit, RotationPartMatchesPolarDecomposition) {
  unsigned state = 7u;
  auto rnd = [&]() {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0 - 0.5;
  };
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    Eigen::Matrix3d M;
    for (int i = 0; i < 9; ++i) M.data()[i] = rnd();
    if (k % 3 == 0) M = Eigen::AngleAxisd(3 * rnd(), Eigen::Vector3d(rnd(), rnd(), rnd()).normalized()) * (0.8 * Eigen::Matrix3d::Identity() + 0.3 * M);
    if (k == 1) M.col(2) = M.col(0) * 2.0;  // singular
    if (k == 2) M.col(1) *= -1.0;          // (possibly) reflected
    const Eigen::Matrix3d R = rotation_part(M);
    worst = std::max(worst, (R - polar_decomposition(M).R).cwiseAbs().maxCoeff());
    EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
  }
  EXPECT_LE(worst, 1e-8);
  EXPECT_TRUE(rotation_part(Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN())).isIdentity());
}

// Golden outputs shared by the native and wasm runs (tolerance 1e-7 in mesh units: the two
// compilers round differently, the solves are otherwise identical).
TEST(Edit, GoldenBarBend) {
  BarCase b = bar_case(true);
  LaplacianEditResult r = laplacian_edit(b.mesh.V, b.mesh.F, b.region, {b.transform});
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  test::expect_golden("edit_bar_bend", r.V, 1e-7);
}

TEST(Edit, GoldenKnightScaleFeatures) {
  Mesh m = load("edit/decimated-knight.ply");
  EditRegion region;
  region.handles = {slab(m.V, 1, 0.2, true)};   // head
  region.fixed = slab(m.V, 1, 0.15, false);     // feet
  const Eigen::Vector3d c = m.V.colwise().mean().transpose();
  const HandleTransform T = HandleTransform::similarity(Eigen::Vector3d(0.05, 0.05, 0), Eigen::Vector3d(0, 0, 1), 0.4,
                                                        c, 1.2);
  LaplacianEditResult r = laplacian_edit(m.V, m.F, region, {T}, {}, FeatureSize::Scale);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_TRUE(inverted_faces(m.V, r.V, m.F).empty());
  test::expect_golden("edit_knight_scale", r.V, 1e-7);
}

}  // namespace
