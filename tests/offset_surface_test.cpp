// Tests of core/cage/offset_surface: the offset surface of real meshes lies at about the
// requested distance from the input surface (measured with the BVH closest point), is a
// closed outward-oriented 2-manifold enclosing the input, reports the grid it used, and bad
// inputs give a status.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "cage/cage_containment.h"
#include "cage/offset_surface.h"
#include "mesh/mesh.h"
#include "mesh/validate.h"
#include "spatial/triangle_bvh.h"
#include "test_support.h"

namespace {

struct DistanceStats {
  double min = 0, max = 0, mean = 0;
};

// Distance of every row of P to the surface (V, F).
DistanceStats distances(const Eigen::MatrixXd& P, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  const mm::TriangleBvh bvh(V, F);
  DistanceStats s;
  s.min = std::numeric_limits<double>::infinity();
  for (int i = 0; i < P.rows(); ++i) {
    const double d = std::sqrt(bvh.closest_point(P.row(i).transpose()).sq_distance);
    s.min = std::min(s.min, d);
    s.max = std::max(s.max, d);
    s.mean += d;
  }
  s.mean /= std::max<Eigen::Index>(P.rows(), 1);
  return s;
}

// Longest side of the bounding box.
double longest_side(const Eigen::MatrixXd& V) { return (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff(); }

}  // namespace

using namespace mm;

class OffsetDistance : public ::testing::TestWithParam<const char*> {};

TEST_P(OffsetDistance, VerticesLieAtTheRequestedDistance) {
  const Mesh m = test::load_mesh(GetParam());
  ASSERT_GT(m.V.rows(), 0);
  OffsetSurfaceOptions opt;
  opt.resolution = 64;
  opt.offset_voxels = 3.0;
  const OffsetSurface o = offset_surface(m.V, m.F, opt);
  ASSERT_TRUE(o.status.ok()) << o.status.message;
  const double h = o.voxel_size;
  EXPECT_NEAR(h, longest_side(m.V) / opt.resolution, 1e-12 * longest_side(m.V));
  EXPECT_NEAR(o.offset, opt.offset_voxels * h, 1e-12 * o.offset);
  ASSERT_GT(o.V.rows(), 100);
  // The level set of the distance to the voxelised solid. The solid is the input dilated by up
  // to about one cell (sampled triangles mark whole cells), so vertices lie between d and
  // d + 2h from the true surface, about d + h on average; never nearer than d − 2h (header).
  const DistanceStats s = distances(o.V, m.V, m.F);
  std::printf("[ offset ] %s: d = %.5f, h = %.5f, vertex distance min %.3f d, mean %.3f d, max %.3f d\n", GetParam(),
              o.offset, h, s.min / o.offset, s.mean / o.offset, s.max / o.offset);
  EXPECT_GE(s.min, o.offset - 0.5 * h);
  EXPECT_LE(s.max, o.offset + 2.0 * h);
  EXPECT_GE(s.mean, o.offset);
  EXPECT_LE(s.mean, o.offset + 1.5 * h);
  // Closed, manifold, consistently and outward oriented; the input is inside it.
  const MeshReport rep = validate_mesh(o.V, o.F);
  EXPECT_TRUE(rep.closed());
  EXPECT_TRUE(rep.status(manifold_defects()).ok()) << rep.to_text();
  EXPECT_EQ(rep.count(MeshDefect::InconsistentOrientation), 0);
  const CageContainment cc = cage_containment(m.V, o.V, o.F, o.offset - 2.0 * h);
  EXPECT_TRUE(cc.not_inside.empty()) << cc.not_inside.size() << " input vertices not inside";
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, OffsetDistance,
                         ::testing::Values("pose/cat-reference.ply", "pose/lion-reference.ply", "edit/bar.ply"));

TEST(OffsetSurface, DistanceFollowsTheRequestedOffset) {
  // Doubling d (same grid) moves the surface out by about d.
  const Mesh m = test::load_mesh("pose/cat-reference.ply");
  OffsetSurfaceOptions opt;
  opt.resolution = 64;
  opt.offset_voxels = 2.5;
  const OffsetSurface near = offset_surface(m.V, m.F, opt);
  opt.offset_voxels = 5.0;
  const OffsetSurface far = offset_surface(m.V, m.F, opt);
  ASSERT_TRUE(near.status.ok() && far.status.ok());
  EXPECT_DOUBLE_EQ(near.voxel_size, far.voxel_size);
  const DistanceStats dn = distances(near.V, m.V, m.F), df = distances(far.V, m.V, m.F);
  EXPECT_NEAR(df.mean - dn.mean, far.offset - near.offset, 0.5 * near.voxel_size);
  // And the explicit voxel size is used as given.
  OffsetSurfaceOptions fixed;
  fixed.voxel_size = 0.02 * longest_side(m.V);
  const OffsetSurface o = offset_surface(m.V, m.F, fixed);
  ASSERT_TRUE(o.status.ok()) << o.status.message;
  EXPECT_DOUBLE_EQ(o.voxel_size, fixed.voxel_size);
}

TEST(OffsetSurface, BadInputsGiveClearStatus) {
  const Mesh m = test::load_mesh("pose/cat-reference.ply");
  EXPECT_EQ(offset_surface(Eigen::MatrixXd(0, 3), Eigen::MatrixXi(0, 3)).status.code, StatusCode::InvalidMesh);
  Eigen::MatrixXd nan = m.V;
  nan(3, 1) = std::nan("");
  EXPECT_EQ(offset_surface(nan, m.F).status.code, StatusCode::InvalidMesh);
  OffsetSurfaceOptions huge;
  huge.max_grid_nodes = 1000;  // the default resolution needs far more nodes
  EXPECT_EQ(offset_surface(m.V, m.F, huge).status.code, StatusCode::InvalidArgument);
}
