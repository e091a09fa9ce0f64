// Tests of core/transfer (issue 4, paper 000): self-transfer, same-connectivity pose pairs with
// exact ground truth (the paper's method against the Lévy and Kovnatsky baselines), cat → lion
// with the repo's landmarks (flips, Γ, golden shared by native and wasm, determinism), bad
// inputs and cancellation.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include <Eigen/Geometry>

#include "common/threads.h"
#include "io/asset.h"
#include "metrics/transfer_metrics.h"
#include "transfer/pose_transfer.h"
#include "io/landmarks_file.h"
#include "test_support.h"

namespace mm::transfer_test {

Mesh load(const std::string& rel) { return test::load_mesh(rel); }

std::vector<LandmarkPair> load_pairs(const std::string& rel) {
  std::vector<LandmarkPair> out;
  const Status s = io::read_landmarks(test::data_path(rel), &out);
  EXPECT_TRUE(s.ok()) << s.message;
  return out;
}

struct MethodScore {
  double error = 0, detail = 0;
};

// Transfers `pose` onto `rest` with each method; errors against the pose itself (exact GT).
std::vector<MethodScore> score_pair(const std::string& pose, const std::string& rest) {
  const Mesh P = load(pose), S = load(rest);
  std::vector<MethodScore> out;
  for (TransferMethod m : {TransferMethod::Yin, TransferMethod::Kovnatsky, TransferMethod::Levy}) {
    PoseTransferOptions opt;
    opt.method = m;
    const PoseTransferResult r = pose_transfer(P, S, {}, opt);
    EXPECT_TRUE(r.status.ok()) << r.status.message;
    const TransferMetrics gt = transfer_metrics(r.V, P.V, S.F);
    const TransferMetrics src = transfer_metrics(r.V, S.V, S.F);
    out.push_back({gt.vertex_error_mean, src.laplacian_change});
    std::printf("[ transfer ] %s -> %s %-9s: error mean %.4f max %.4f | detail: |δ| change %.4f, edge %.4f, flips %d | Γ dom %.2f | %d it, %.0f ms\n",
                pose.c_str(), rest.c_str(), transfer_method_name(m), gt.vertex_error_mean, gt.vertex_error_max,
                src.laplacian_change, src.edge_distortion_mean, src.flipped_faces, r.gamma_dominance, r.iterations,
                r.ms.total);
  }
  return out;
}

}  // namespace mm::transfer_test

using namespace mm;

TEST(TransferSelf, ReferenceEqualsSourceGivesSource) {
  const Mesh lion = transfer_test::load("pose/lion-reference.ply");
  const PoseTransferResult r = pose_transfer(lion, lion, {});
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const double err = (r.V - lion.V).rowwise().norm().maxCoeff() / bounding_box_diagonal(lion.V);
  EXPECT_LE(err, 1e-6);
  EXPECT_EQ(r.landmarks.size(), 30u);
}

// Same-connectivity pairs with exact ground truth (docs/transfer.md has the table). The paper's
// method must beat both coefficient-swap baselines on pose error and on detail preservation.
struct PosePair {
  const char* pose;
  const char* rest;
  double max_error;  // measured value + margin (native Release, 450-vertex cage)
  // Kovnatsky's coefficient swap is a coin flip on some pairs: over 12 phases of the cage's
  // voxel grid the paper's method had the lower pose error in 7 of 12 on cat-05 and 3 of 12 on
  // lion-01 (docs/transfer.md, "The cage's grid phase"). There it must stay within this factor
  // of Kovnatsky's error; 0 = strictly below it.
  double kovnatsky_factor = 0;
};

class TransferPose : public testing::TestWithParam<PosePair> {};

TEST_P(TransferPose, PaperMethodBeatsBothBaselines) {
  const PosePair& p = GetParam();
  const auto s = transfer_test::score_pair(p.pose, p.rest);
  ASSERT_EQ(s.size(), 3u);
  if (p.kovnatsky_factor > 0)
    EXPECT_LT(s[0].error, p.kovnatsky_factor * s[1].error) << "Yin vs Kovnatsky pose error";
  else
    EXPECT_LT(s[0].error, s[1].error) << "Yin vs Kovnatsky pose error";
  EXPECT_LT(s[0].error, s[2].error) << "Yin vs Lévy pose error";
  EXPECT_LT(s[0].detail, s[1].detail) << "Yin vs Kovnatsky detail";
  EXPECT_LT(s[0].detail, s[2].detail) << "Yin vs Lévy detail";
  EXPECT_LT(s[0].error, p.max_error);
}

INSTANTIATE_TEST_SUITE_P(TransferPairs, TransferPose,
                         testing::Values(PosePair{"pose/cat-07.ply", "pose/cat-reference.ply", 0.12},
                                         PosePair{"pose/lion-05.ply", "pose/lion-reference.ply", 0.05},
                                         PosePair{"pose/cat-05.ply", "pose/cat-reference.ply", 0.072, 1.03},
                                         PosePair{"pose/lion-01.ply", "pose/lion-reference.ply", 0.092, 1.06}),
                         [](const testing::TestParamInfo<PosePair>& info) {
                           std::string n = info.param.pose;
                           n = n.substr(n.find('/') + 1);
                           n = n.substr(0, n.find('.'));
                           n.erase(std::remove(n.begin(), n.end(), '-'), n.end());
                           return n;
                         });

// cat-01 (large hip rotation): the one pair where Kovnatsky's coefficient swap has the lower pose
// error (0.056 vs 0.069). It is not a local minimum of Eq. 12: starting the cage solve from the
// ground truth fitted in the cage subspace, or from the Kovnatsky result, returns to the same
// minimum (docs/transfer.md). Yin still beats Lévy on error and Kovnatsky on detail; against
// Lévy's detail (0.104) it is a coin flip of the cage's grid phase (0.095–0.111 over 12 phases,
// 0.106 at the default), so there it must stay within 5 %.
TEST(TransferPoseCat01, BeatsLevyAndKeepsDetail) {
  const auto s = transfer_test::score_pair("pose/cat-01.ply", "pose/cat-reference.ply");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_LT(s[0].error, s[2].error) << "Yin vs Lévy pose error";
  EXPECT_LT(s[0].detail, s[1].detail) << "Yin vs Kovnatsky detail";
  EXPECT_LT(s[0].detail, 1.05 * s[2].detail) << "Yin vs Lévy detail";
  EXPECT_LT(s[0].error, 0.075);
}

// cage_pose_energy (exact Procrustes similarities): zero regularity terms for similarities of the
// rest cage, (s − 1)² per vertex for a uniform scale, ‖P C − T‖² for the data term.
TEST(TransferCageEnergy, ExactSimilarityTerms) {
  CagePoseProblem prob;
  prob.C.resize(6, 3);
  prob.C << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  prob.CF.resize(8, 3);
  prob.CF << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  prob.P.resize(2, 6);
  prob.P << 0.3, 0.1, 0.2, 0.2, 0.1, 0.1, 0.5, -0.2, 0.1, 0.3, 0.2, 0.1;
  prob.T.resize(2, 3);
  prob.T << 0.1, 0.2, 0.3, -0.1, 0.0, 0.4;
  const CagePoseEnergy rest = cage_pose_energy(prob, prob.C);
  EXPECT_NEAR(rest.lf, (prob.P * prob.C - prob.T).squaredNorm(), 1e-14);
  EXPECT_NEAR(rest.lc, 0, 1e-24);
  EXPECT_NEAR(rest.sf, 0, 1e-24);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::MatrixXd moved = (prob.C * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
  const CagePoseEnergy rigid = cage_pose_energy(prob, moved);
  EXPECT_NEAR(rigid.lc, 0, 1e-20);
  EXPECT_NEAR(rigid.sf, 0, 1e-20);
  const CagePoseEnergy scaled = cage_pose_energy(prob, 1.1 * moved);
  EXPECT_NEAR(scaled.lc, 0, 1e-20);
  EXPECT_NEAR(scaled.sf, 6 * 0.01, 1e-12);
  const CagePoseOptions opt;
  EXPECT_NEAR(scaled.total, scaled.lf + opt.lambda1 * scaled.lc + opt.lambda2 * scaled.sf, 1e-14);
}

TEST(TransferDifferentConnectivity, CatToLionGoldenAndDeterministic) {
  const Mesh cat = transfer_test::load("pose/cat-01.ply");
  const Mesh lion = transfer_test::load("pose/lion-reference.ply");
  const Mesh lion01 = transfer_test::load("pose/lion-01.ply");
  const auto pairs = transfer_test::load_pairs("landmarks/cat-lion.json");
  const PoseTransferResult a = pose_transfer(cat, lion, pairs);
  ASSERT_TRUE(a.status.ok()) << a.status.message;
  const TransferMetrics src = transfer_metrics(a.V, lion.V, lion.F);
  EXPECT_EQ(src.flipped_faces, 0);
  EXPECT_GT(a.gamma_dominance, 1.0) << a.gamma;
  // lion-01 is Sumner's transfer of cat-01 (a rough ground truth, placed in its own frame):
  // compare after removing the centroid offset.
  const Eigen::RowVector3d offset = lion01.V.colwise().mean() - a.V.colwise().mean();
  const Eigen::MatrixXd centred = a.V.rowwise() + offset;
  const TransferMetrics gt = transfer_metrics(centred, lion01.V, lion.F);
  std::printf("[ transfer ] cat-01 -> lion: error vs lion-01 mean %.4f max %.4f | |δ| change %.4f, edge %.4f, flips %d | Γ dom %.2f | %d it\n",
              gt.vertex_error_mean, gt.vertex_error_max, src.laplacian_change, src.edge_distortion_mean,
              src.flipped_faces, a.gamma_dominance, a.iterations);
  EXPECT_LT(gt.vertex_error_mean, 0.15);
  // Determinism: a second run is bit-identical, also on one thread (natively the cage and the
  // mean-value coordinates otherwise run beside the eigenbases; common/threads.h).
  set_max_threads(1);
  const PoseTransferResult b = pose_transfer(cat, lion, pairs);
  set_max_threads(0);
  ASSERT_TRUE(b.status.ok());
  EXPECT_TRUE(a.V == b.V) << "one thread and the default differ";
  // Golden (shared by the native and wasm runs): every 50th vertex. Tolerance 1e-3 mesh units
  // (≈ 1e-3 of the lion's 1.09 bbox diagonal, 100× below the pose error above): the cage is
  // bit-identical on both targets, but the eigensolver (Eigen vectorises with SSE natively,
  // not in wasm) and libm (glibc vs musl) differ in the last bits, and the iterative coupling and
  // the re-linearized cage solve amplify that to ~2.4e-4 (measured wasm vs native). Within one
  // target the result is bit-identical (checked above).
  Eigen::MatrixXd sample((a.V.rows() + 49) / 50, 3);
  for (int i = 0; i < sample.rows(); ++i) sample.row(i) = a.V.row(50 * i);
  test::expect_golden("transfer_cat01_lion", sample, 1e-3);
}

// A given cage with its least-weighted vertices held (PoseTransferOptions::fixed_cage_weight, the
// part transfer's reuse of the level-1 cage, paper 000 Sec. 5): the held vertices move together,
// by the placement's translation alone; with none held, the given cage gives the automatic
// transfer exactly. (On a whole body even the lightest 1 % anchors limbs that must turn — cat-05's
// aligned error 0.053 → 0.173 with 17 of 450 held — which is why only parts hold them: there the
// lightest lie on the far side of the body.)
TEST(TransferGivenCage, LeastWeightedCageVerticesAreHeld) {
  const Mesh P = transfer_test::load("pose/cat-05.ply"), S = transfer_test::load("pose/cat-reference.ply");
  const PoseTransferResult first = pose_transfer(P, S, {});
  ASSERT_TRUE(first.status.ok()) << first.status.message;
  const Mesh cage{first.cage_rest, first.cage_faces};
  const PoseTransferResult same = pose_transfer(P, S, {}, {}, {}, &cage);
  ASSERT_TRUE(same.status.ok()) << same.status.message;
  EXPECT_EQ(same.fixed_cage_vertices, 0);
  EXPECT_TRUE(same.V == first.V) << "the automatic cage given back gives another result";
  PoseTransferOptions opt;
  opt.fixed_cage_weight = 0.01;  // the part transfer's default
  const PoseTransferResult r = pose_transfer(P, S, {}, opt, {}, &cage);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const long m = r.cage_rest.rows();
  EXPECT_GT(r.fixed_cage_vertices, 0);
  EXPECT_LT(r.fixed_cage_vertices, m / 10);
  // The largest group of cage vertices that moved by one and the same vector holds the held ones.
  const Eigen::MatrixXd D = r.cage_deformed - r.cage_rest;
  const double tol = 1e-6 * bounding_box_diagonal(r.cage_rest);
  long largest = 0;
  for (long i = 0; i < m; ++i) largest = std::max(largest, static_cast<long>(((D.rowwise() - D.row(i)).rowwise().norm().array() < tol).count()));
  std::printf("[ transfer ] cat-05 in its own cage: %d of %ld cage vertices held, %ld moved by one vector\n", r.fixed_cage_vertices, m, largest);
  EXPECT_GE(largest, r.fixed_cage_vertices);
  EXPECT_LT(largest, m);
}

TEST(TransferErrors, BadInputsGiveClearStatus) {
  const Mesh cat = transfer_test::load("pose/cat-reference.ply");
  const Mesh lion = transfer_test::load("pose/lion-reference.ply");
  // Different connectivity without landmarks.
  PoseTransferResult r = pose_transfer(cat, lion, {});
  EXPECT_EQ(r.status.code, StatusCode::InvalidArgument);
  EXPECT_NE(r.status.message.find("different connectivity"), std::string::npos) << r.status.message;
  // Landmark out of range.
  std::vector<LandmarkPair> pairs = transfer_test::load_pairs("landmarks/cat-lion.json");
  pairs[2].source = 5000;
  r = pose_transfer(cat, lion, pairs);
  EXPECT_EQ(r.status.code, StatusCode::InvalidArgument);
  EXPECT_NE(r.status.message.find("source vertex 5000 is out of range"), std::string::npos) << r.status.message;
  // Too few landmarks.
  r = pose_transfer(cat, lion, {{0, 0}, {10, 10}, {20, 20}});
  EXPECT_EQ(r.status.code, StatusCode::InvalidArgument);
  EXPECT_NE(r.status.message.find("only 3 landmark pairs"), std::string::npos) << r.status.message;
  // Mesh too coarse for k' eigenpairs: an octahedron.
  Mesh tiny;
  tiny.V.resize(6, 3);
  tiny.V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  tiny.F.resize(8, 3);
  tiny.F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  r = pose_transfer(tiny, tiny, {});
  EXPECT_EQ(r.status.code, StatusCode::InvalidMesh);
  EXPECT_NE(r.status.message.find("too coarse"), std::string::npos) << r.status.message;
  // Inconsistent options.
  PoseTransferOptions bad;
  bad.num_low_frequencies = 12;
  EXPECT_EQ(pose_transfer(cat, cat, {}, bad).status.code, StatusCode::InvalidArgument);
  // A user cage that misses the mesh.
  Mesh box;
  box.V.resize(8, 3);
  box.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  box.V *= 0.01;
  box.F.resize(12, 3);
  box.F << 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3;
  r = pose_transfer(cat, cat, {}, {}, {}, &box);
  EXPECT_EQ(r.status.code, StatusCode::InvalidMesh);
  EXPECT_NE(r.status.message.find("cage encloses"), std::string::npos) << r.status.message;
}

TEST(TransferProgress, ReportsStagesAndCancels) {
  const Mesh lion = transfer_test::load("pose/lion-reference.ply");
  std::vector<std::string> stages;
  double last = 0;
  bool monotone = true;
  Progress p([&](const std::string& stage, double f) {
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
    monotone = monotone && f >= last - 1e-12;
    last = f;
    return stage != "mean-value coordinates";  // cancel once MVC starts
  });
  PoseTransferResult r = pose_transfer(lion, lion, {}, {}, p);
  EXPECT_EQ(r.status.code, StatusCode::Cancelled);
  EXPECT_TRUE(monotone);
  ASSERT_GE(stages.size(), 3u);
  EXPECT_EQ(stages.front(), "eigenbasis");
  TransferMethod m;
  EXPECT_TRUE(parse_transfer_method("kovnatsky", &m));
  EXPECT_EQ(m, TransferMethod::Kovnatsky);
  EXPECT_FALSE(parse_transfer_method("sumner", &m));
  // A whole transfer (cage, optimisation, fold and flip checks): the bar only moves forward.
  test::ForwardProgress fp;
  const Mesh cat = transfer_test::load("pose/cat-01.ply");
  r = pose_transfer(cat, lion, transfer_test::load_pairs("landmarks/cat-lion.json"), {}, fp.sink());
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_TRUE(fp.backwards.empty()) << fp.backwards.front();
  EXPECT_GE(fp.reports, 10);
}
