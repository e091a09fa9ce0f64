// Tests of core/edit (paper 001 implicit Laplacian editing) and core/metrics/edit_metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "edit/implicit_gradients.h"
#include "edit/laplacian_editor.h"
#include "edit/selection.h"
#include "io/asset.h"
#include "mesh/mesh.h"
#include "metrics/edit_metrics.h"
#include "test_support.h"

namespace {

using namespace mm;

Mesh edit_test_load(const std::string& rel) {
  io::LoadResult r = io::load_asset(test::data_path(rel));
  EXPECT_TRUE(r.status.ok()) << rel << ": " << r.status.message;
  return r.asset.mesh();
}

// Vertices whose coordinate `axis` lies in the lowest / highest `fraction` of the extent.
std::vector<int> edit_test_slab(const Eigen::MatrixXd& V, int axis, double fraction, bool high) {
  const double lo = V.col(axis).minCoeff(), hi = V.col(axis).maxCoeff();
  std::vector<int> out;
  for (int i = 0; i < V.rows(); ++i) {
    const double t = (V(i, axis) - lo) / (hi - lo);
    if (high ? t >= 1 - fraction : t <= fraction) out.push_back(i);
  }
  return out;
}

int edit_test_long_axis(const Eigen::MatrixXd& V) {
  Eigen::Index a;
  (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff(&a);
  return static_cast<int>(a);
}

TEST(EditProbe, DISABLED_Print) {
  for (const char* p : {"edit/bar.ply", "anim/human_woman.ply", "edit/decimated-knight.ply", "edit/armadillo.ply"}) {
    Mesh m = edit_test_load(p);
    std::printf("%s V=%d F=%d min=(%g %g %g) max=(%g %g %g)\n", p, m.num_vertices(), m.num_faces(),
                m.V.col(0).minCoeff(), m.V.col(1).minCoeff(), m.V.col(2).minCoeff(), m.V.col(0).maxCoeff(),
                m.V.col(1).maxCoeff(), m.V.col(2).maxCoeff());
  }
}

}  // namespace
