// Tests of core/retarget (paper 002): MFS kernel derivatives, harmonic map fit, joint matching
// and errors, synthesis, self-retargeting on synthetic and real characters, the LBS baseline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>

#include "io/asset.h"
#include "io/gltf_animation.h"
#include "io/joints_json.h"
#include "app/joints_job.h"
#include "app/retarget_job.h"
#include "mesh/mesh.h"
#include "metrics/retarget_metrics.h"
#include "retarget/harmonic_map.h"
#include "retarget/harmonic_retarget.h"
#include "character/joint_set.h"
#include "retarget/lbs_baseline.h"
#include "retarget/mfs_kernel.h"
#include "common/threads.h"
#include "test_support.h"

namespace {

// A closed tube along +y (radius r, length h) with `rings` rings of `segs` vertices and caps:
//      ___
//     |   |  ← tip (y = h)
//     |   |
//     |___|  ← base (y = 0)
void tube(double r, double h, int rings, int segs, Eigen::MatrixXd* V, Eigen::MatrixXi* F) {
  V->resize(rings * segs + 2, 3);
  for (int i = 0; i < rings; ++i)
    for (int s = 0; s < segs; ++s) {
      const double a = 2 * M_PI * s / segs;
      V->row(i * segs + s) << r * std::cos(a), h * i / (rings - 1), r * std::sin(a);
    }
  const int bottom = rings * segs, top = bottom + 1;
  V->row(bottom) << 0, 0, 0;
  V->row(top) << 0, h, 0;
  std::vector<Eigen::Vector3i> f;
  for (int i = 0; i + 1 < rings; ++i)
    for (int s = 0; s < segs; ++s) {
      const int a = i * segs + s, b = i * segs + (s + 1) % segs, c = a + segs, d = b + segs;
      f.push_back({a, c, d});
      f.push_back({a, d, b});
    }
  for (int s = 0; s < segs; ++s) {
    f.push_back({bottom, s, (s + 1) % segs});
    f.push_back({top, (rings - 1) * segs + (s + 1) % segs, (rings - 1) * segs + s});
  }
  F->resize(f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) F->row(i) = f[i].transpose();
}

// Two-bone skinning of the tube: the upper bone turns by `angle` about z through the middle
// joint; weights blend over a band of ±0.15 h around it.
Eigen::MatrixXd bend(const Eigen::MatrixXd& V, double h, double angle) {
  Eigen::MatrixXd out = V;
  const Eigen::Vector3d pivot(0, h / 2, 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (int i = 0; i < V.rows(); ++i) {
    const double y = V(i, 1);
    const double w = std::clamp((y - (h / 2 - 0.15 * h)) / (0.3 * h), 0.0, 1.0);
    const Eigen::Vector3d p = V.row(i).transpose();
    out.row(i) = ((1 - w) * p + w * (R * (p - pivot) + pivot)).transpose();
  }
  return out;
}

mm::JointSet tube_joints(double h) {
  mm::JointSet J;
  J.names = {"root", "mid", "tip"};
  J.P.resize(3, 3);
  J.P << 0, 0.1 * h, 0, 0, 0.5 * h, 0, 0, 0.9 * h, 0;
  J.parent = {-1, 0, 1};
  return J;
}

double mean_distance(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  return (A - B).rowwise().norm().mean();
}

}  // namespace

TEST(RetargetKernel, DerivativesMatchFiniteDifferences) {
  Eigen::MatrixXd X(2, 3), Q(3, 3);
  X << 0.1, 0.2, -0.3, 0.5, -0.1, 0.2;
  Q << 2, 0, 0, -1, 1.5, 0.5, 0.3, -2, 1;
  const Eigen::MatrixXd D = mm::mfs_gradient(X, Q), H = mm::mfs_hessian(X, Q);
  const double e = 1e-5;
  for (int i = 0; i < X.rows(); ++i)
    for (int d = 0; d < 3; ++d) {
      Eigen::MatrixXd Xp = X.row(i), Xm = X.row(i);
      Xp(0, d) += e;
      Xm(0, d) -= e;
      const Eigen::MatrixXd g = (mm::mfs_kernel(Xp, Q) - mm::mfs_kernel(Xm, Q)) / (2 * e);
      EXPECT_LT((g - D.row(3 * i + d)).norm(), 1e-8);
      // Diagonal second derivative, and harmonicity: the trace of the Hessian vanishes.
      const Eigen::MatrixXd g2 = (mm::mfs_gradient(Xp, Q) - mm::mfs_gradient(Xm, Q)) / (2 * e);
      EXPECT_LT((g2.row(d) - H.row(6 * i + d)).norm(), 1e-6);
    }
  const Eigen::MatrixXd trace = H.middleRows(0, 1) + H.middleRows(1, 1) + H.middleRows(2, 1);
  EXPECT_LT(trace.norm(), 1e-12);
}

// The per-frame vertex product (Ktᵀ times three columns) splits its columns across the task
// threads (common/threads.h parallel_blocks): the same bits on 1, 2 and 4 threads, and the plain
// product to rounding.
TEST(RetargetKernel, TransposedProductIsTheSameOnAnyThreadCount) {
  const Eigen::MatrixXd Mt = Eigen::MatrixXd::Random(263, 7001), B = Eigen::MatrixXd::Random(263, 3);
  Eigen::MatrixXd out[3];
  const int counts[3] = {1, 2, 4};
  for (int t = 0; t < 3; ++t) {
    mm::set_max_threads(counts[t]);
    out[t] = mm::transposed_times_n3(Mt, B);
  }
  mm::set_max_threads(0);
  EXPECT_TRUE(out[0] == out[1]);
  EXPECT_TRUE(out[0] == out[2]);
  EXPECT_LT((out[0] - Mt.transpose() * B).cwiseAbs().maxCoeff(), 1e-12);
  // The summation order is fixed (even terms, odd terms, then their sum; the SIMD lanes are the
  // two chains), so native and wasm give the same bits: equal to this plain loop, for an even and
  // an odd number of terms.
  for (const int k : {263, 264}) {
    const Eigen::MatrixXd M2 = Eigen::MatrixXd::Random(k, 501), B2 = Eigen::MatrixXd::Random(k, 3);
    const Eigen::MatrixXd got = mm::transposed_times_n3(M2, B2);
    Eigen::MatrixXd want(M2.cols(), 3);
    for (int j = 0; j < M2.cols(); ++j)
      for (int c = 0; c < 3; ++c) {
        double even = 0, odd = 0;
        for (int i = 0; i < k; ++i) (i % 2 == 0 ? even : odd) += M2(i, j) * B2(i, c);
        want(j, c) = even + odd;
      }
    EXPECT_TRUE(got == want) << k << " terms: max difference " << (got - want).cwiseAbs().maxCoeff();
  }
}

TEST(RetargetHarmonicMap, FitsRigidAndBentTube) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  tube(0.15, 1.0, 21, 16, &V, &F);
  mm::MfsHarmonicMap map;
  mm::HarmonicMapOptions o;
  o.singularities.offset = 0.15;  // far singularities fit smooth maps best (the default trades this for thin gaps)
  ASSERT_TRUE(map.build(V, F, o).ok());
  EXPECT_EQ(map.num_singularities(), 260);
  // Identity and a rigid motion are harmonic: reproduced almost exactly on the surface.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::MatrixXd Vr = V * R.transpose();
  Vr.rowwise() += Eigen::RowVector3d(0.3, -0.2, 0.1);
  const Eigen::MatrixXd K = mm::mfs_kernel(V, map.singularities());
  EXPECT_LT(mean_distance(K * map.fit(V), V), 3e-4);
  EXPECT_LT(mean_distance(K * map.fit(Vr), Vr), 3e-4);
  // The Jacobian of the rigid fit at an interior point is R.
  Eigen::MatrixXd x(1, 3);
  x << 0, 0.5, 0;
  const Eigen::Matrix3d J = (mm::mfs_gradient(x, map.singularities()) * map.fit(Vr)).transpose();
  EXPECT_LT((J - R).norm(), 1e-2);
  // A 60° bend is fitted to a fraction of a percent of the length.
  const Eigen::MatrixXd Vb = bend(V, 1.0, M_PI / 3);
  EXPECT_LT(mean_distance(K * map.fit(Vb), Vb), 5e-3);
}

// ---------------------------------------------------------------- joints and their errors
TEST(RetargetJoints, ParseAndMatchErrors) {
  EXPECT_EQ(mm::io::parse_joints_json("[1,2]").status.code, mm::StatusCode::ParseError);
  EXPECT_EQ(mm::io::parse_joints_json("{\"a\": [1, 2]}").status.code, mm::StatusCode::ParseError);
  const mm::io::JointSetResult j = mm::io::parse_joints_json("{\"mid\": [0, 0.5, 0], \"root\": [0, 0.1, 0], \"foo\": [0, 0.9, 0]}");
  ASSERT_TRUE(j.status.ok());
  EXPECT_TRUE(j.joints.from_user);
  const mm::JointSet src = tube_joints(1.0);
  // "foo" matches no source joint: a user-placed joint that is never used is an error.
  const mm::JointMatchResult m = mm::match_joints(src, j.joints);
  EXPECT_EQ(m.status.code, mm::StatusCode::InvalidArgument);
  EXPECT_NE(m.status.message.find("foo"), std::string::npos) << m.status.message;
  // An explicit map fixes it; a map naming a missing joint is an error.
  EXPECT_TRUE(mm::match_joints(src, j.joints, {{"tip", "foo"}}).status.ok());
  const mm::JointMatchResult bad = mm::match_joints(src, j.joints, {{"elbow", "foo"}});
  EXPECT_EQ(bad.status.code, mm::StatusCode::InvalidArgument);
  EXPECT_NE(bad.status.message.find("elbow"), std::string::npos);
  // Names match ignoring case and separators.
  mm::JointSet t = src;
  t.names = {"ROOT", "Mid", "t_i_p"};
  EXPECT_EQ(mm::match_joints(src, t).pairs.size(), 3u);
}

TEST(RetargetJoints, MissingAndOutsideJointsAreErrors) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  tube(0.15, 1.0, 21, 16, &V, &F);
  mm::RetargetCharacter S{V, F, tube_joints(1.0)};
  mm::RetargetCharacter T{V, F, {}};
  mm::HarmonicRetargeter r;
  mm::Status s = r.precompute(S, T);
  EXPECT_EQ(s.code, mm::StatusCode::InvalidArgument);
  EXPECT_NE(s.message.find("no joints"), std::string::npos) << s.message;
  T.joints = tube_joints(1.0);
  T.joints.from_user = true;
  T.joints.P(2, 0) = 0.5;  // "tip" well outside the tube
  s = r.precompute(S, T);
  EXPECT_EQ(s.code, mm::StatusCode::InvalidArgument);
  EXPECT_NE(s.message.find("'tip' lies outside"), std::string::npos) << s.message;
}

// ---------------------------------------------------------------- synthesis on a synthetic limb
TEST(RetargetSynthetic, SelfRetargetingBentTubeAndWeightReading) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  tube(0.15, 1.0, 21, 16, &V, &F);
  mm::RetargetCharacter C{V, F, tube_joints(1.0)};
  auto error = [&](const mm::HarmonicRetargetOptions& o) {
    mm::HarmonicRetargeter r;
    EXPECT_TRUE(r.precompute(C, C, {}, o).ok());
    double e = 0;
    for (double a : {0.0, 0.5, 1.0}) {
      const Eigen::MatrixXd Vb = bend(V, 1.0, a);
      const mm::RetargetFrame f = r.retarget(Vb);
      EXPECT_TRUE(f.status.ok());
      e += mean_distance(f.V, Vb) / 3;
    }
    return e;
  };
  mm::HarmonicRetargetOptions ours;  // λ_smooth = 0.001, λ_position = 10 (the text's principles)
  ours.articulated_base = false;     // the paper's maps alone: this is about reading its weights
  mm::HarmonicRetargetOptions literal = ours;  // the list read in its printed order
  literal.w_smooth = 10;
  literal.w_position = 0.01;
  mm::HarmonicRetargetOptions joints_only = ours;  // the paper's descriptors: joints only
  joints_only.surface_descriptors = 0;
  joints_only.bone_samples = 0;
  const double e_ours = error(ours), e_literal = error(literal), e_joints = error(joints_only);
  RecordProperty("error_ours", std::to_string(e_ours));
  RecordProperty("error_literal_weights", std::to_string(e_literal));
  RecordProperty("error_joints_only", std::to_string(e_joints));
  EXPECT_LT(e_ours, 0.01);               // of the tube length
  EXPECT_GT(e_literal, 5 * e_ours);      // λ_smooth = 10 flattens the bend
  EXPECT_GE(e_joints, e_ours);
}

// ---------------------------------------------------------------- real characters (glTF)
namespace {

struct Job {
  mm::io::LoadResult src, tgt;
  mm::app::RetargetJob session;
  mm::Status status;
};

std::unique_ptr<Job> job(const std::string& src, const std::string& tgt, const std::string& clip, double fps,
                         int last_frame, const std::string& joints_file = "",
                         mm::app::RetargetMethod method = mm::app::RetargetMethod::Harmonic,
                         const std::function<void(mm::HarmonicRetargetOptions&)>& tweak = {},
                         const mm::Progress& progress = {}) {
  auto j = std::make_unique<Job>();
  j->src = mm::io::load_asset(mm::test::data_path(src));
  j->tgt = mm::io::load_asset(mm::test::data_path(tgt));
  if (!j->src.status.ok() || !j->tgt.status.ok()) {
    j->status = j->src.status.ok() ? j->tgt.status : j->src.status;
    return j;
  }
  std::string joints;
  if (!joints_file.empty()) {
    std::ifstream in(mm::test::data_path(joints_file));
    std::stringstream ss;
    ss << in.rdbuf();
    joints = ss.str();
  }
  mm::app::RetargetJobOptions o;
  o.clip = clip;
  o.fps = fps;
  o.last_frame = last_frame;
  o.method = method;
  if (tweak) tweak(o.harmonic);
  j->status = j->session.prepare(j->src.asset, j->tgt.asset, joints, "", o, progress);
  return j;
}

double height(const Eigen::MatrixXd& V) { return V.col(1).maxCoeff() - V.col(1).minCoeff(); }

// The articulated base (off by default: docs/retarget.md "Articulated base").
void base_on(mm::HarmonicRetargetOptions& h) { h.articulated_base = true; }

// Self-retargeting error (Eq. 19, per frame mean vertex distance / height) over the sampled clip.
mm::SequenceError self_error(const Job& j) {
  std::vector<Eigen::MatrixXd> out, gt;
  EXPECT_TRUE(j.session.frames(0, j.session.num_frames(), &out).ok());
  for (int k = 0; k < j.session.num_frames(); ++k) gt.push_back(j.session.source_frame(k));
  return mm::sequence_vertex_error(out, gt, height(j.session.target_rest()));
}

}  // namespace

TEST(RetargetReal, SelfRetargetingCesiumMan) {
  auto j = job("anim/CesiumMan/CesiumMan.glb", "anim/CesiumMan/CesiumMan.glb", "", 10, -1, "",
               mm::app::RetargetMethod::Harmonic, base_on);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  const mm::SequenceError e = self_error(*j);
  RecordProperty("mean_error_over_height", std::to_string(e.mean));
  RecordProperty("max_frame_error_over_height", std::to_string(e.max));
  std::cout << "[ CesiumMan self-retargeting ] mean " << e.mean << " max frame " << e.max << " of height\n";
  // Issue 15: stays <= 0.005. Measured 0.00079 with the articulated base on the source's skin
  // weights (the default), 0.0011 with learned weights, 0.0042 with the paper's maps alone.
  EXPECT_LE(e.mean, 0.005);
}

// The KayKit characters are six interpenetrating parts (legs and arms buried in the body) that
// move differently where they touch; one harmonic map over their union fits them less well than
// a single skin (docs/retarget.md, "Why KayKit needs a larger budget").
void larger_budget(mm::HarmonicRetargetOptions& h) {
  h.map.singularities.count = 600;
  h.map.num_collocation = 2500;
  h.w_bone = 0.3;
}

TEST(RetargetReal, SelfRetargetingKayKitKnight) {
  auto j = job("anim/KayKit/Knight.glb", "anim/KayKit/Knight.glb", "Walking_A", 10, -1, "",
               mm::app::RetargetMethod::Harmonic, base_on);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  // Identical characters: every descriptor's source point is the target point itself, also for
  // surface points that a ray from their bone reaches only through a buried part's surface.
  const mm::HarmonicRetargeter& H = j->session.harmonic();
  EXPECT_LT((H.source_descriptors() - H.target_descriptors()).cwiseAbs().maxCoeff(), 1e-12);
  const mm::SequenceError e = self_error(*j);
  RecordProperty("mean_error_over_height", std::to_string(e.mean));
  std::cout << "[ Knight self-retargeting, articulated base ] mean " << e.mean << " max frame " << e.max << " of height\n";
  // Issue 15: <= 0.006. Measured 0.0016 with the articulated base on the skin's weights (0.0039
  // with learned weights): the bones' motions carry the six rigid parts and the map the rest.
  EXPECT_LE(e.mean, 0.006);
  // The paper's maps alone: with 260 singularities the MFS fit (Eq. 13) of the six parts is 0.011
  // of the height (0.014 measured); regression guard.
  auto paper = job("anim/KayKit/Knight.glb", "anim/KayKit/Knight.glb", "Walking_A", 10, -1, "",
                   mm::app::RetargetMethod::Harmonic, [](mm::HarmonicRetargetOptions& h) { h.articulated_base = false; });
  ASSERT_TRUE(paper->status.ok()) << paper->status.message;
  const mm::SequenceError ep = self_error(*paper);
  std::cout << "[ Knight self-retargeting, paper's maps alone ] mean " << ep.mean << " of height\n";
  EXPECT_LE(ep.mean, 0.015);
  EXPECT_LT(e.mean, 0.5 * ep.mean);
  // The paper's maps with 600 singularities, 2500 collocation points and λ_bone = 0.3 (bone
  // lengths held less stiffly: the harmonic map's interior at the joints does not follow the
  // skeleton exactly).
  auto b = job("anim/KayKit/Knight.glb", "anim/KayKit/Knight.glb", "Walking_A", 10, -1, "",
               mm::app::RetargetMethod::Harmonic, [](mm::HarmonicRetargetOptions& h) {
                 larger_budget(h);
                 h.articulated_base = false;
               });
  ASSERT_TRUE(b->status.ok()) << b->status.message;
  const mm::SequenceError eb = self_error(*b);
  RecordProperty("mean_error_over_height_larger_budget", std::to_string(eb.mean));
  std::cout << "[ Knight self-retargeting, 600 singularities ] mean " << eb.mean << " max frame " << eb.max
            << " of height\n";
  EXPECT_LE(eb.mean, 0.01);
}

TEST(RetargetReal, SelfRetargetingKayKitBarbarian) {
  auto j = job("anim/KayKit/Barbarian.glb", "anim/KayKit/Barbarian.glb", "Walking_A", 10, -1, "",
               mm::app::RetargetMethod::Harmonic, base_on);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  const mm::SequenceError e = self_error(*j);
  RecordProperty("mean_error_over_height", std::to_string(e.mean));
  std::cout << "[ Barbarian self-retargeting ] mean " << e.mean << " max frame " << e.max << " of height\n";
  // Issue 15: <= 0.006. Measured 0.0021 with the articulated base (0.0049 with learned weights,
  // 0.013 with the paper's maps).
  EXPECT_LE(e.mean, 0.006);
}

TEST(RetargetReal, KnightToBarbarianHarmonicVsLbs) {
  // Issue 15: <= 0.008 of the height against Barbarian's own clip, on Walking_A and an arm-heavy
  // clip. Measured (Walking_A / Cheer): the articulated base with the Knight's skin weights and
  // the Barbarian's own skin (the default for a rigged target) 0.0024 / 0.0034; the Barbarian
  // treated as unrigged (the Knight's weights carried over) 0.0044 / 0.0048; weights learned from
  // 16 poses over all of the Knight's clips, carried over 0.0075 / 0.0074; the paper's maps alone
  // 0.0219 / 0.0154; LBS 0.0031 / 0.0030.
  for (const char* clip_name : {"Walking_A", "Cheer"}) {
  auto h = job("anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", clip_name, 10, -1, "",
               mm::app::RetargetMethod::Harmonic, base_on);
  auto l = job("anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", clip_name, 10, -1, "",
               mm::app::RetargetMethod::Lbs);
  ASSERT_TRUE(h->status.ok()) << h->status.message;
  ASSERT_TRUE(l->status.ok()) << l->status.message;
  // Ground truth: Barbarian's own skinned clip of the same name at the same times.
  const mm::AnimatedCharacter& barb = *h->session.target_character();
  int clip = -1;
  ASSERT_TRUE(mm::find_clip(barb, clip_name, &clip).ok());
  std::vector<Eigen::MatrixXd> gt, vh, vl;
  for (int k = 0; k < h->session.num_frames(); ++k) gt.push_back(mm::pose_at(barb, clip, h->session.times()[k]));
  ASSERT_TRUE(h->session.frames(0, h->session.num_frames(), &vh).ok());
  ASSERT_TRUE(l->session.frames(0, l->session.num_frames(), &vl).ok());
  const double H = height(barb.V_rest);
  const mm::SequenceError eh = mm::sequence_vertex_error(vh, gt, H), el = mm::sequence_vertex_error(vl, gt, H);
  RecordProperty("harmonic_error_over_height", std::to_string(eh.mean));
  RecordProperty("lbs_error_over_height", std::to_string(el.mean));
  std::cout << "[ Knight -> Barbarian vs Barbarian's own " << clip_name << " ] harmonic " << eh.mean << ", LBS "
            << el.mean << " of height\n";
  EXPECT_LE(eh.mean, 0.008) << clip_name;
  EXPECT_LE(eh.mean, 3 * el.mean) << clip_name;     // the issue: within 3x of the LBS baseline
  EXPECT_LE(eh.mean, 1.25 * el.mean) << clip_name;  // measured 0.78x / 1.13x
  EXPECT_LT(el.mean, 0.05) << clip_name;
  // The Barbarian treated as unrigged (its skin's weights off, the Knight's carried over), and
  // the source's weights learned from poses instead of its skin (a source whose skin does not
  // describe its motion, e.g. baked simulation): both within the bound, both worse.
  double prev = eh.mean;
  for (const bool learn : {false, true}) {
    auto v = job("anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", clip_name, 10, -1, "",
                 mm::app::RetargetMethod::Harmonic, [&](mm::HarmonicRetargetOptions& o) {
                   o.base_target_skin = false;
                   o.base_skin_weights = !learn;
                 });
    ASSERT_TRUE(v->status.ok()) << v->status.message;
    std::vector<Eigen::MatrixXd> vw;
    ASSERT_TRUE(v->session.frames(0, v->session.num_frames(), &vw).ok());
    const double e = mm::sequence_vertex_error(vw, gt, H).mean;
    std::cout << "[ Knight -> Barbarian vs Barbarian's own " << clip_name << ", target weights carried over"
              << (learn ? ", source weights learned" : "") << " ] " << e << "\n";
    EXPECT_LE(e, 0.008) << clip_name;
    EXPECT_LT(prev, e) << clip_name;
    prev = e;
  }
  }
}

TEST(RetargetReal, FoxToWolfWithPlacedJoints) {
  auto j = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Walk", 15, -1, "joints/wolf0_joints.json",
               mm::app::RetargetMethod::Harmonic, base_on);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  const mm::HarmonicRetargeter& H = j->session.harmonic();
  EXPECT_EQ(H.used_joints().size(), 22u);
  std::vector<Eigen::MatrixXd> joints;
  const double diag = mm::bounding_box_diagonal(j->session.target_rest());
  for (int k = 0; k < j->session.num_frames(); ++k) {
    const mm::RetargetFrame f = H.retarget(j->session.source_frame(k));
    ASSERT_TRUE(f.status.ok());
    // No exploding frames: every vertex stays within half the size of its rest position.
    EXPECT_LT((f.V - j->session.target_rest()).rowwise().norm().maxCoeff(), 0.5 * diag) << "frame " << k;
    joints.push_back(f.joints);
  }
  const mm::BoneLengthError be = mm::bone_length_error(joints, H.bones(), H.rest_bone_lengths());
  RecordProperty("bone_length_error_mean", std::to_string(be.mean));
  RecordProperty("bone_length_error_max", std::to_string(be.max));
  std::cout << "[ Fox -> wolf0 ] bone-length error mean " << be.mean << " max " << be.max << "\n";
  // Issue 15: not worse than the paper's maps alone (mean 0.029). Measured 0.0097 with the
  // articulated base on the Fox's skin weights, 0.016 with learned weights.
  EXPECT_LE(be.mean, 0.029);
  EXPECT_LT(be.max, 0.3);
}

// The page's progress bar: the precompute's fractions (maps, sampling, SVD, factor) and then the
// frames' only move forward.
TEST(RetargetReal, ProgressOnlyMovesForward) {
  mm::test::ForwardProgress fp;
  auto j = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Walk", 15, 3, "joints/wolf0_joints.json",
               mm::app::RetargetMethod::Harmonic, {}, fp.sink());
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  EXPECT_GE(fp.reports, 4);
  EXPECT_TRUE(fp.backwards.empty()) << fp.backwards.front();
  mm::test::ForwardProgress frames_fp;
  std::vector<Eigen::MatrixXd> frames;
  ASSERT_TRUE(j->session.frames(0, 3, &frames, frames_fp.sink()).ok());
  EXPECT_TRUE(frames_fp.backwards.empty()) << frames_fp.backwards.front();
}

TEST(RetargetReal, MultiPartRobotExpressive) {
  // 19 primitives, rigid parts parented to bones plus skinned hands: no welding anywhere.
  auto j = job("anim/RobotExpressive/RobotExpressive.glb", "anim/RobotExpressive/RobotExpressive.glb", "Wave", 10, 6);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  EXPECT_EQ(j->session.source_character().parts.size(), 19u);
  const mm::SequenceError e = self_error(*j);
  std::cout << "[ RobotExpressive self-retargeting ] mean " << e.mean << " of height\n";
  // Issue 15: <= 0.006. Its rig hangs the torso mesh under Body (not the spine), the feet under
  // an IK root outside the mesh and animates the face by morph targets: the base takes each
  // part's bone from the skin (leaf joints get bones of their own) and the maps carry the morphs.
  // Measured 2.7e-5 (0.0098 with learned weights and no leaf bones, 0.011 with the maps alone).
  EXPECT_LE(e.mean, 0.006);
}

TEST(RetargetReal, PropsFollowTheirJointsInTheExportedGlb) {
  // Knight → Barbarian: the Barbarian's axes, shield, mug, hat and cape hang under joint nodes;
  // the exported GLB animates those joints so the props move with the retargeted surface.
  auto j = job("anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", "Walking_A", 10, 8);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  std::vector<Eigen::MatrixXd> frames;
  ASSERT_TRUE(j->session.frames(0, j->session.num_frames(), &frames).ok());
  std::vector<double> times = j->session.times();
  for (double& t : times) t -= j->session.times().front();
  std::vector<uint8_t> glb;
  ASSERT_TRUE(j->session.write_glb(frames, times, &glb).ok());
  {
    std::ofstream out(mm::test::scratch_path("retarget_props.glb"), std::ios::binary);  // glTF-Validator (JS tests)
    out.write(reinterpret_cast<const char*>(glb.data()), static_cast<std::streamsize>(glb.size()));
  }
  const mm::AnimatedCharacter& barb = *j->session.target_character();
  const std::vector<mm::NodeTrack> tracks = mm::prop_tracks(barb, frames);
  std::set<std::string> followed;
  for (const auto& t : tracks)
    for (int p : t.props) followed.insert(barb.node_names[p]);
  for (const char* name : {"1H_Axe", "Barbarian_Round_Shield", "Barbarian_Hat", "Barbarian_Cape"})
    EXPECT_TRUE(followed.count(name)) << name << " does not follow a joint";

  // Read the GLB back and evaluate its animation: each prop's motion (world at the frame ×
  // world at rest⁻¹) is the rigid motion of its joint's anchor vertices, and that rigid motion
  // keeps the anchor vertices (hand, head, chest) close to the retargeted surface.
  mm::io::LoadResult back = mm::io::load_asset_from_memory(glb, mm::io::Format::Glb, "retarget_props.glb");
  ASSERT_TRUE(back.status.ok()) << back.status.message;
  mm::io::CharacterResult bc = mm::io::animated_character(back.asset);
  ASSERT_TRUE(bc.status.ok()) << bc.status.message;
  ASSERT_EQ(bc.character.clips.size(), 1u);
  const double H = height(barb.V_rest);
  const mm::Matrix4dList rest = mm::node_world_matrices(bc.character, -1, 0);
  double export_error = 0, largest_turn = 0;
  for (const auto& t : tracks) {
    double sum = 0;
    int count = 0;
    for (size_t f = 0; f < frames.size(); ++f) {
      const mm::Matrix4dList world = mm::node_world_matrices(bc.character, 0, times[f]);
      const Eigen::Matrix4d expected = t.world[f] * rest[t.node].inverse();
      for (int p : t.props) {
        const Eigen::Matrix4d M = world[p] * rest[p].inverse();
        export_error = std::max(export_error, (M.topLeftCorner<3, 3>() - expected.topLeftCorner<3, 3>()).norm() +
                                                  (M.topRightCorner<3, 1>() - expected.topRightCorner<3, 1>()).norm() / H);
        largest_turn = std::max(largest_turn, Eigen::AngleAxisd(Eigen::Matrix3d(M.topLeftCorner<3, 3>())).angle());
      }
      for (int v : t.anchor_vertices) {
        const Eigen::Vector3d x = barb.V_rest.row(v).transpose();
        sum += (expected.topLeftCorner<3, 3>() * x + expected.topRightCorner<3, 1>() - frames[f].row(v).transpose()).norm();
        ++count;
      }
    }
    const double mean_fit = sum / count / H;
    std::cout << "[ props ] " << barb.node_names[t.node] << " follows " << barb.node_names[t.anchor_joint] << " ("
              << t.anchor_vertices.size() << " vertices): mean rigid-fit distance " << mean_fit << " of height\n";
    EXPECT_LT(mean_fit, 0.02) << barb.node_names[t.node];
  }
  std::cout << "[ props ] exported motion vs computed: " << export_error << ", largest turn " << largest_turn << " rad\n";
  EXPECT_LT(export_error, 1e-4);  // float32 keys
  EXPECT_GT(largest_turn, 0.1);   // the props do turn (a walk swings the hands)
}

TEST(RetargetReal, ClipNotFoundListsClips) {
  auto j = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Gallop", 15, -1, "joints/wolf0_joints.json");
  EXPECT_EQ(j->status.code, mm::StatusCode::InvalidArgument);
  EXPECT_NE(j->status.message.find("Survey"), std::string::npos) << j->status.message;
  auto k = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Walk", 15, -1);  // no joints for a PLY
  EXPECT_EQ(k->status.code, mm::StatusCode::InvalidArgument);
}

// The whole harmonic path must be continuous in the target's joints (thirty-third session). The
// surface descriptors' source counterparts (bone_correspondence) go through each point's nearest
// bone; a point whose nearest point on two bones is their shared joint was decided by the last
// bits of p + 1·(c − p) against c: moving every joint of Fox → wolf0 by 1e-9 moved a frame by
// 0.37 units (4e-3 of the height; 5 of 400 descriptors changed bones), which made the page and the
// CLI differ on automatic joints. A clamped point is now the joint bit for bit: 4.4e-9 units.
TEST(RetargetReal, ContinuousInTheTargetJoints) {
  std::ifstream in(mm::test::data_path("joints/wolf0_joints.json"));
  std::stringstream ss;
  ss << in.rdbuf();
  const mm::io::JointSetResult J = mm::io::parse_joints_json(ss.str());
  ASSERT_TRUE(J.status.ok());
  mm::JointSet moved = J.joints;
  moved.P.array() += 1e-9;
  auto frames = [&](const std::string& joints) {
    auto j = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Walk", 30, 12);
    mm::app::RetargetJobOptions o;
    o.clip = "Walk";
    o.fps = 30;
    o.last_frame = 12;
    j->status = j->session.prepare(j->src.asset, j->tgt.asset, joints, "", o);
    EXPECT_TRUE(j->status.ok()) << j->status.message;
    std::vector<Eigen::MatrixXd> out;
    EXPECT_TRUE(j->session.frames(0, 12, &out).ok());
    return out;
  };
  const auto a = frames(mm::app::joints_json_text(J.joints)), b = frames(mm::app::joints_json_text(moved));
  ASSERT_EQ(a.size(), b.size());
  const double h = a[0].col(2).maxCoeff() - a[0].col(2).minCoeff();  // wolf0 is z-up
  double worst = 0;
  for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, (a[k] - b[k]).rowwise().norm().maxCoeff() / h);
  std::cout << "[ Fox -> wolf0, every joint moved by 1e-9 ] largest change over 12 frames " << worst << " of the height\n";
  EXPECT_LT(worst, 1e-7);
}

// Golden frames shared by native and wasm. The MFS sampling is discrete (farthest points, inside
// tests), so the calibration surface is snapped to a grid before it (harmonic_map.cpp): with
// that, Fox → wolf0 agrees natively and in wasm to ~1e-12 relative.
TEST(RetargetGolden, FoxToWolfFrames) {
  auto j = job("anim/Fox/glTF-Binary/Fox.glb", "anim/wolf0.ply", "Walk", 15, 3, "joints/wolf0_joints.json");
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  std::vector<Eigen::MatrixXd> frames;
  ASSERT_TRUE(j->session.frames(0, 3, &frames).ok());
  // Every 97th vertex of 3 frames (wolf0 is ~190 units across; 1e-3 absolute ≈ 5e-6 relative).
  const int n = static_cast<int>(frames[0].rows()) / 97 + 1;
  Eigen::MatrixXd G(3 * n, 3);
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < n; ++i) G.row(f * n + i) = frames[f].row(std::min<int>(i * 97, frames[f].rows() - 1));
  mm::test::expect_golden("retarget_fox_wolf", G, 1e-3);
}

// Knight → Barbarian (skinned target, interpenetrating parts). Agrees natively and in wasm to
// 1e-9 now; one earlier build differed by 2.3e-4, hence 1e-3 (4e-4 of the Barbarian's height).
TEST(RetargetGolden, KnightToBarbarianFrames) {
  auto j = job("anim/KayKit/Knight.glb", "anim/KayKit/Barbarian.glb", "Walking_A", 10, 3);
  ASSERT_TRUE(j->status.ok()) << j->status.message;
  std::vector<Eigen::MatrixXd> frames;
  ASSERT_TRUE(j->session.frames(0, 3, &frames).ok());
  // Every 37th vertex of 3 frames; tolerance see above.
  const int n = static_cast<int>(frames[0].rows()) / 37 + 1;
  Eigen::MatrixXd G(3 * n, 3);
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < n; ++i) G.row(f * n + i) = frames[f].row(std::min<int>(i * 37, frames[f].rows() - 1));
  mm::test::expect_golden("retarget_knight_barbarian", G, 1e-3);
}


// The articulated base must be continuous in its input: a first version jumped with last-bit
// differences (learned-weight active sets, hard weight thresholds, a top-4 cut, ray decisions),
// so that native and wasm differed by 1.5% of the height at one vertex. Moving every input vertex
// by 1e-13 of the height must move no output vertex by more than 1e-3 of the height: measured
// 3.9e-5 (the learned weights amplify, smoothly; 5 poses here, 16 in the job); before the fixes
// the same kind of change moved a Barbarian vertex by 0.13 of the height, a wolf vertex by 0.21.
TEST(RetargetReal, ArticulatedBaseIsContinuousInItsInput) {
  const mm::io::LoadResult src = mm::io::load_asset(mm::test::data_path("anim/KayKit/Knight.glb"));
  const mm::io::LoadResult tgt = mm::io::load_asset(mm::test::data_path("anim/KayKit/Barbarian.glb"));
  ASSERT_TRUE(src.status.ok() && tgt.status.ok());
  const mm::io::CharacterResult s = mm::io::animated_character(src.asset), t = mm::io::animated_character(tgt.asset);
  ASSERT_TRUE(s.status.ok() && t.status.ok());
  int clip = -1;
  ASSERT_TRUE(mm::find_clip(s.character, "Walking_A", &clip).ok());
  std::vector<Eigen::MatrixXd> poses;
  for (double u : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    const mm::AnimationClip& c = s.character.clips[clip];
    poses.push_back(mm::pose_at(s.character, clip, c.start + u * (c.end - c.start)));
  }
  const double h = height(t.character.V_rest);
  auto run = [&](double eps, bool skin) {
    // Each vertex (source rest and poses, target rest) moved by eps·h in a direction of its own
    // (a scaling would be undone exactly by the working frames).
    auto nudge = [&](Eigen::MatrixXd V) {
      for (Eigen::Index i = 0; i < V.rows(); ++i)
        V.row(i) += eps * h * Eigen::RowVector3d(std::sin(1.3 * i), std::cos(2.1 * i), std::sin(0.7 * i + 1));
      return V;
    };
    const mm::JointSet J = mm::character_joints(s.character);
    const mm::RetargetCharacter S{nudge(s.character.V_rest), s.character.F, J,
                                  skin ? mm::joint_skin_weights(s.character, J) : mm::SkinWeights{}};
    const mm::RetargetCharacter T{nudge(t.character.V_rest), t.character.F, mm::character_joints(t.character)};
    std::vector<Eigen::MatrixXd> frames;
    for (const auto& P : poses) frames.push_back(nudge(P));
    mm::HarmonicRetargeter H;
    H.set_base_frames(frames);
    mm::HarmonicRetargetOptions o;
    o.articulated_base = true;
    EXPECT_TRUE(H.precompute(S, T, {}, o).ok());
    std::vector<Eigen::MatrixXd> out;
    for (const auto& P : frames) out.push_back(H.retarget(P).V);
    return out;
  };
  for (bool skin : {true, false}) {
    const auto a = run(0, skin), b = run(1e-13, skin);
    double worst = 0;
    for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, (a[k] - b[k]).rowwise().norm().maxCoeff() / h);
    std::cout << "[ articulated base, " << (skin ? "skin" : "learned") << " weights, 1e-13 input change ] largest output change "
              << worst << " of the height\n";
    EXPECT_LT(worst, 1e-3);
  }
}

