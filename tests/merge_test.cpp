// Mesh merging (paper 001 Sec. 5, 6) and the cut utility, on real meshes from data/.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Geometry>

#include "io/asset.h"
#include "merge/cut.h"
#include "merge/mesh_merge.h"
#include "mesh/mesh.h"
#include "mesh/topology.h"
#include "operators/operators.h"
#include "test_support.h"

namespace mm {
namespace {

using test::load_mesh;

// The vertex of `loop` with the largest (or smallest) coordinate `axis`.
int loop_extreme(const Eigen::MatrixXd& V, const std::vector<int>& loop, int axis, bool largest) {
  int best = loop[0];
  for (int v : loop)
    if (largest ? V(v, axis) > V(best, axis) : V(v, axis) < V(best, axis)) best = v;
  return best;
}

// The horse without its head: a plane through the neck (tosca horse0: z up, head towards −y).
Mesh horse_body() {
  const Mesh horse = load_mesh("pose/horse0.ply");
  const CutResult c = cut_plane(horse.V, horse.F, {0, -85, 140}, Eigen::Vector3d(0, -1, 1), {0, 0, 100});
  EXPECT_TRUE(c.status.ok()) << c.status.message;
  return {c.V, c.F};
}

// The camel's head and neck (data/edit/camelhead.ply: y up, one open boundary at the neck).
Mesh camel_head() { return load_mesh("edit/camelhead.ply"); }

struct Topology {
  int boundary_loops = 0, nonmanifold_edges = 0, degenerate_faces = 0;
};

Topology topology_of(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  Topology t;
  t.boundary_loops = static_cast<int>(boundary_loops(F, static_cast<int>(V.rows())).size());
  for (const EdgeUse& e : edge_uses(F)) t.nonmanifold_edges += e.faces > 2;
  const Eigen::VectorXd A = face_areas(V, F);
  const double diag = bounding_box_diagonal(V);
  for (int f = 0; f < F.rows(); ++f) t.degenerate_faces += A[f] <= 1e-12 * diag * diag;
  return t;
}

Eigen::MatrixXd apply_similarity(const Eigen::MatrixXd& V, const Eigen::Matrix3d& R, double s, const Eigen::Vector3d& t) {
  return ((s * R * V.transpose()).colwise() + t).transpose();
}

MergeInput head_on_neck() {
  const Mesh body = horse_body(), head = camel_head();
  MergeInput in;
  in.target_V = body.V;
  in.target_F = body.F;
  in.source_V = head.V;
  in.source_F = head.F;
  const auto tl = boundary_loops(body.F, body.num_vertices());
  const auto sl = boundary_loops(head.F, head.num_vertices());
  EXPECT_EQ(tl.size(), 1u);
  EXPECT_EQ(sl.size(), 1u);
  MergeBoundaryPair p;
  // Top and bottom of each neck (horse: z up; camel: y up).
  p.target_keys = {loop_extreme(body.V, tl[0], 2, true), loop_extreme(body.V, tl[0], 2, false)};
  p.source_keys = {loop_extreme(head.V, sl[0], 1, true), loop_extreme(head.V, sl[0], 1, false)};
  in.pairs.push_back(p);
  std::printf("keys: target %d %d, source %d %d\n", p.target_keys[0], p.target_keys[1], p.source_keys[0], p.source_keys[1]);
  return in;
}

TEST(Cut, PlaneCutLeavesOneCleanLoop) {
  const Mesh horse = load_mesh("pose/horse0.ply");
  const CutResult c = cut_plane(horse.V, horse.F, {0, -85, 140}, Eigen::Vector3d(0, -1, 1), {0, 0, 100});
  ASSERT_TRUE(c.status.ok()) << c.status.message;
  EXPECT_EQ(c.boundary_loops, 1);
  const Topology t = topology_of(c.V, c.F);
  EXPECT_EQ(t.nonmanifold_edges, 0);
  EXPECT_EQ(t.degenerate_faces, 0);
  // Everything kept lies on the kept side of the plane.
  const Eigen::Vector3d n = Eigen::Vector3d(0, -1, 1).normalized();
  for (int v = 0; v < c.V.rows(); ++v) EXPECT_LE(n.dot(c.V.row(v).transpose() - Eigen::Vector3d(0, -85, 140)), 1e-9);
  EXPECT_LT(c.V.rows(), horse.V.rows());
  EXPECT_GT(c.V.rows(), horse.V.rows() / 2);
}

TEST(Merge, HeadOntoNeckIsWatertightAndClean) {
  const MergeInput in = head_on_neck();
  const MergeResult r = merge_meshes(in);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  const Topology t = topology_of(r.V, r.F);
  ASSERT_EQ(r.stats.seams.size(), 1u);
  const MergeSeamReport& s = r.stats.seams[0];
  std::printf("merge head→neck: %d+%d vertices, %d constraints (+%d refined), zip %d faces, min angle %.1f°, "
              "dihedral max %.1f° mean %.1f°, flipped %d; precompute %.0f ms, solve %.0f ms, zip %.0f ms\n",
              r.stats.target_vertices, r.stats.source_vertices, r.stats.boundary_constraints,
              r.stats.refined_vertices, s.zip_faces, s.min_angle_deg, s.dihedral_max_deg, s.dihedral_mean_deg,
              s.flipped_faces, r.stats.precompute_ms, r.stats.solve_ms, r.stats.zip_ms);
  EXPECT_TRUE(io::save_mesh(test::scratch_path("merge_head_on_neck.ply"), r.V, r.F).ok());
  EXPECT_EQ(t.boundary_loops, 0);  // 1 + 1 − 2 per merged pair
  EXPECT_EQ(t.nonmanifold_edges, 0);
  EXPECT_EQ(t.degenerate_faces, 0);
  EXPECT_EQ(s.flipped_faces, 0);
  EXPECT_GT(s.min_angle_deg, 5.0);
}

}  // namespace
}  // namespace mm

namespace mm {
namespace {

// Fig. 1: the same merge whatever the source's position, orientation and scale.
TEST(Merge, ConfigurationIndependent) {
  const MergeInput base = head_on_neck();
  const MergeResult r0 = merge_meshes(base);
  ASSERT_TRUE(r0.status.ok()) << r0.status.message;
  const double diag = bounding_box_diagonal(r0.V);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1), scale(std::log(0.3), std::log(3.0));
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(3.1 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized()).toRotationMatrix();
    const double s = std::exp(scale(rng));
    const Eigen::Vector3d t(100 * unit(rng), 100 * unit(rng), 100 * unit(rng));
    MergeInput in = base;
    in.source_V = apply_similarity(base.source_V, R, s, t);
    const MergeResult r = merge_meshes(in);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.V.rows(), r0.V.rows());
    ASSERT_TRUE(r.F == r0.F);
    const double err = (r.V - r0.V).rowwise().norm().maxCoeff() / diag;
    std::printf("configuration %d (scale %.2f): max vertex difference %.2e of the diagonal\n", trial, s, err);
    EXPECT_LE(err, 1e-9);
  }
}

}  // namespace
}  // namespace mm
