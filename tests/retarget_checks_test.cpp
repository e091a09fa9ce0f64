// The per-frame checks of a retargeting (app::RetargetJob::frames with FrameChecks): what the
// page plots under its timeline. Fox's Survey onto the wolf with its placed joints (harmonic), and
// the LBS baseline, on real characters from data/anim.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "app/retarget_job.h"
#include "io/asset.h"
#include "metrics/retarget_metrics.h"
#include "test_support.h"

namespace mm {
namespace {

std::string rc_read(const std::string& rel) {
  std::ifstream in(test::data_path(rel));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct RcPair {
  io::LoadResult fox = io::load_asset(test::data_path("anim/Fox/glTF-Binary/Fox.glb"));
  io::LoadResult wolf = io::load_asset(test::data_path("anim/wolf0.ply"));
  std::string joints = rc_read("joints/wolf0_joints.json");
};

TEST(RetargetChecks, PerFrameBoneErrorAndIntersectionsMatchTheMetrics) {
  const RcPair p;
  ASSERT_TRUE(p.fox.status.ok() && p.wolf.status.ok());
  app::RetargetJobOptions opt;
  opt.fps = 10;
  opt.last_frame = 6;
  app::RetargetJob job;
  ASSERT_TRUE(job.prepare(p.fox.asset, p.wolf.asset, p.joints, "", opt).ok());
  std::vector<Eigen::MatrixXd> frames;
  app::RetargetJob::FrameChecks checks;
  ASSERT_TRUE(job.frames(1, 4, &frames, {}, &checks).ok());
  ASSERT_EQ(frames.size(), 4u);
  ASSERT_EQ(checks.bone_length_error.size(), 4u);
  ASSERT_EQ(checks.self_intersections.size(), 4u);
  // Each value is the metric of that frame alone: the map's joints f_t(J_t) and the surface.
  const std::vector<std::pair<int, int>> rest = intersecting_triangle_pairs(job.target_rest(), job.target_faces());
  for (int k = 0; k < 4; ++k) {
    const RetargetFrame f = job.harmonic().retarget(job.source_frame(1 + k));
    ASSERT_TRUE(f.status.ok());
    EXPECT_EQ((f.V - frames[k]).cwiseAbs().maxCoeff(), 0.0) << "frame " << k;
    const double e = bone_length_error({f.joints}, job.harmonic().bones(), job.harmonic().rest_bone_lengths()).mean;
    EXPECT_EQ(checks.bone_length_error[k], e) << "frame " << k;
    EXPECT_GT(e, 0.0);
    EXPECT_LT(e, 0.2);
    EXPECT_EQ(checks.self_intersections[k], self_intersection_count(frames[k], job.target_faces(), rest)) << "frame " << k;
    EXPECT_GE(checks.self_intersections[k], 0);
  }
  // Without checks: the same frames, nothing else asked.
  std::vector<Eigen::MatrixXd> plain;
  ASSERT_TRUE(job.frames(1, 4, &plain).ok());
  for (int k = 0; k < 4; ++k) EXPECT_EQ((plain[k] - frames[k]).cwiseAbs().maxCoeff(), 0.0);
}

TEST(RetargetChecks, LbsHasNoMapJointsButCountsIntersections) {
  const RcPair p;
  ASSERT_TRUE(p.fox.status.ok() && p.wolf.status.ok());
  app::RetargetJobOptions opt;
  opt.fps = 10;
  opt.last_frame = 3;
  opt.method = app::RetargetMethod::Lbs;
  app::RetargetJob job;
  ASSERT_TRUE(job.prepare(p.fox.asset, p.wolf.asset, p.joints, "", opt).ok());
  std::vector<Eigen::MatrixXd> frames;
  app::RetargetJob::FrameChecks checks;
  ASSERT_TRUE(job.frames(0, 3, &frames, {}, &checks).ok());
  ASSERT_EQ(checks.bone_length_error.size(), 3u);
  for (double e : checks.bone_length_error) EXPECT_TRUE(std::isnan(e));
  for (int c : checks.self_intersections) EXPECT_GE(c, 0);
}

}  // namespace
}  // namespace mm
