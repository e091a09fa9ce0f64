// Tests of core/cage/hull_decimation: on the offset surface of a real mesh, the decimated hull
// reaches the target, stays a closed consistently oriented 2-manifold of the same topology,
// keeps every input vertex inside and at least the clearance away; without points to keep it
// cuts through the mesh (so the enclosure checks above can fail); bad inputs give a status.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cage/cage_containment.h"
#include "cage/hull_decimation.h"
#include "cage/offset_surface.h"
#include "mesh/mesh.h"
#include "mesh/validate.h"
#include "spatial/triangle_bvh.h"
#include "test_support.h"

namespace {

struct Hull {
  mm::Mesh mesh;            // the input mesh (points to keep inside)
  mm::OffsetSurface offset; // the surface that is decimated
  double clearance = 0;
};

// Offset surface of the cat at a coarse grid (fast), clearance 0.2% of the diagonal as the
// enclosing cage uses by default.
const Hull& cat_hull() {
  static const Hull h = [] {
    Hull out;
    out.mesh = mm::test::load_mesh("pose/cat-reference.ply");
    mm::OffsetSurfaceOptions oo;
    oo.resolution = 64;
    out.offset = mm::offset_surface(out.mesh.V, out.mesh.F, oo);
    out.clearance = 2e-3 * mm::bounding_box_diagonal(out.mesh.V);
    return out;
  }();
  return h;
}

// Smallest distance from the rows of P to the surface (V, F).
double min_distance(const Eigen::MatrixXd& P, const Eigen::MatrixXd& V, const Eigen::MatrixXi& F) {
  const mm::TriangleBvh bvh(V, F);
  double d2 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < P.rows(); ++i) d2 = std::min(d2, bvh.closest_point(P.row(i).transpose()).sq_distance);
  return std::sqrt(d2);
}

}  // namespace

using namespace mm;

TEST(HullDecimation, ReachesTargetClosedManifoldAndEnclosesEveryVertex) {
  const Hull& h = cat_hull();
  ASSERT_TRUE(h.offset.status.ok()) << h.offset.status.message;
  const MeshReport in = validate_mesh(h.offset.V, h.offset.F);
  ASSERT_TRUE(in.closed());
  HullDecimationOptions opt;
  opt.target_vertices = 400;
  ASSERT_GT(h.offset.V.rows(), 4 * opt.target_vertices);
  const HullDecimation d = hull_decimation(h.offset.V, h.offset.F, h.mesh.V, h.clearance, opt);
  ASSERT_TRUE(d.status.ok()) << d.status.message;
  // Each collapse removes one vertex and two faces; decimation stops at the target.
  EXPECT_LE(d.V.rows(), opt.target_vertices);
  EXPECT_EQ(d.V.rows() + d.collapses, h.offset.V.rows());
  EXPECT_EQ(d.F.rows() + 2 * d.collapses, h.offset.F.rows());
  // Closed, manifold, consistently oriented, same topology as the input surface.
  const MeshReport rep = validate_mesh(d.V, d.F);
  EXPECT_TRUE(rep.closed());
  EXPECT_TRUE(rep.status(manifold_defects()).ok()) << rep.to_text();
  EXPECT_EQ(rep.count(MeshDefect::InconsistentOrientation), 0);
  EXPECT_EQ(rep.count(MeshDefect::DegenerateFace), 0);
  EXPECT_EQ(rep.euler_characteristic, in.euler_characteristic);
  EXPECT_EQ(rep.num_components, in.num_components);
  // Every input vertex inside (winding number 1) and no nearer to the hull than the clearance.
  const CageContainment cc = cage_containment(h.mesh.V, d.V, d.F, 0.0);
  EXPECT_TRUE(cc.not_inside.empty()) << cc.not_inside.size() << " vertices outside";
  EXPECT_GE(min_distance(h.mesh.V, d.V, d.F), h.clearance * (1 - 1e-9));
  // Outward oriented: the enclosed volume is positive.
  double volume6 = 0;
  for (int f = 0; f < d.F.rows(); ++f) {
    const Eigen::Vector3d a = d.V.row(d.F(f, 0)), b = d.V.row(d.F(f, 1)), c = d.V.row(d.F(f, 2));
    volume6 += a.dot(b.cross(c));
  }
  EXPECT_GT(volume6, 0);
}

TEST(HullDecimation, WithoutPointsTheHullCutsThroughTheMesh) {
  // The same decimation with nothing to keep inside goes much further into the shape: this is
  // what the point tests prevent (and shows the enclosure checks above can fail).
  const Hull& h = cat_hull();
  ASSERT_TRUE(h.offset.status.ok()) << h.offset.status.message;
  HullDecimationOptions opt;
  opt.target_vertices = 20;
  const HullDecimation d = hull_decimation(h.offset.V, h.offset.F, Eigen::MatrixXd(0, 3), 0.0, opt);
  ASSERT_TRUE(d.status.ok()) << d.status.message;
  EXPECT_LE(d.V.rows(), opt.target_vertices);
  // Some vertices end up outside, or closer to the hull than the clearance the tests keep.
  const CageContainment cc = cage_containment(h.mesh.V, d.V, d.F, h.clearance);
  EXPECT_GT(cc.not_inside.size(), 0u);
  const MeshReport rep = validate_mesh(d.V, d.F);
  EXPECT_TRUE(rep.closed());
  EXPECT_TRUE(rep.status(manifold_defects()).ok()) << rep.to_text();
}

TEST(HullDecimation, DeterministicAndStallsAboveAnUnreachableTarget) {
  const Hull& h = cat_hull();
  ASSERT_TRUE(h.offset.status.ok()) << h.offset.status.message;
  HullDecimationOptions opt;
  opt.target_vertices = 4;  // far below what can enclose the cat
  const HullDecimation a = hull_decimation(h.offset.V, h.offset.F, h.mesh.V, h.clearance, opt);
  ASSERT_TRUE(a.status.ok()) << a.status.message;
  EXPECT_GT(a.V.rows(), 4);
  const CageContainment cc = cage_containment(h.mesh.V, a.V, a.F, 0.0);
  EXPECT_TRUE(cc.not_inside.empty()) << cc.not_inside.size() << " vertices outside";
  const HullDecimation b = hull_decimation(h.offset.V, h.offset.F, h.mesh.V, h.clearance, opt);
  EXPECT_TRUE(a.V == b.V) << "two runs gave different hulls";
  EXPECT_TRUE(a.F == b.F);
}

TEST(HullDecimation, BadInputsGiveClearStatus) {
  const Hull& h = cat_hull();
  HullDecimationOptions opt;
  opt.target_vertices = 3;
  EXPECT_EQ(hull_decimation(h.offset.V, h.offset.F, h.mesh.V, 0.0, opt).status.code, StatusCode::InvalidArgument);
  opt.target_vertices = 100;
  Eigen::MatrixXi bad = h.offset.F;
  bad(5, 1) = static_cast<int>(h.offset.V.rows());
  const HullDecimation d = hull_decimation(h.offset.V, bad, h.mesh.V, 0.0, opt);
  EXPECT_EQ(d.status.code, StatusCode::InvalidMesh);
  EXPECT_NE(d.status.message.find("face 5"), std::string::npos) << d.status.message;
  Eigen::MatrixXd nan = h.offset.V;
  nan(0, 0) = std::nan("");
  EXPECT_EQ(hull_decimation(nan, h.offset.F, h.mesh.V, 0.0, opt).status.code, StatusCode::InvalidMesh);
}
