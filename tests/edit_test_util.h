// Shared helpers of the edit test files (tests/edit_test.cpp, tests/edit_probe_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "edit/laplacian_editor.h"
#include "io/asset.h"
#include "mesh/mesh.h"
#include "mesh/midpoint_subdivide.h"
#include "test_support.h"

namespace mm::edit_test {

inline Mesh load(const std::string& rel) {
  io::LoadResult r = io::load_asset(test::data_path(rel));
  EXPECT_TRUE(r.status.ok()) << rel << ": " << r.status.message;
  return r.asset.mesh();
}

// Vertices whose coordinate `axis` lies in the lowest / highest `fraction` of the extent.
inline std::vector<int> slab(const Eigen::MatrixXd& V, int axis, double fraction, bool high) {
  const double lo = V.col(axis).minCoeff(), hi = V.col(axis).maxCoeff();
  std::vector<int> out;
  for (int i = 0; i < V.rows(); ++i) {
    const double t = (V(i, axis) - lo) / (hi - lo);
    if (high ? t >= 1 - fraction : t <= fraction) out.push_back(i);
  }
  return out;
}

inline int long_axis(const Eigen::MatrixXd& V) {
  Eigen::Index a;
  (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff(&a);
  return static_cast<int>(a);
}

struct BarCase {
  Mesh mesh;
  EditRegion region;
  HandleTransform transform;
};


// Closed slender cylinder along x (radius r, length len, `around` × `along` quads split into
// triangles, alternate rings rotated by half a step, flat caps fanned from their centres). CCW
// from outside. Used for the bend/twist comparisons on a thin part (len / r = 20 by default).
inline Mesh slender_cylinder(double r = 0.05, double len = 1.0, int around = 24, int along = 100) {
  Mesh m;
  m.V.resize((along + 1) * around + 2, 3);
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < around; ++i) {
      const double a = 2 * M_PI * (i + 0.5 * (j % 2)) / around;
      m.V.row(j * around + i) << -len / 2 + len * j / along, r * std::cos(a), r * std::sin(a);
    }
  const int c0 = (along + 1) * around, c1 = c0 + 1;
  m.V.row(c0) << -len / 2, 0, 0;
  m.V.row(c1) << len / 2, 0, 0;
  std::vector<Eigen::RowVector3i> F;
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      const int a = j * around + i, b = j * around + (i + 1) % around, c = a + around, d = b + around;
      if (j % 2 == 0) {
        F.emplace_back(a, b, c);
        F.emplace_back(b, d, c);
      } else {
        F.emplace_back(a, d, c);
        F.emplace_back(a, b, d);
      }
    }
  for (int i = 0; i < around; ++i) {
    F.emplace_back(c0, (i + 1) % around, i);
    F.emplace_back(c1, along * around + i, along * around + (i + 1) % around);
  }
  m.F.resize(static_cast<Eigen::Index>(F.size()), 3);
  for (size_t f = 0; f < F.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = F[f];
  return m;
}

BarCase bar_case_of(Mesh mesh, bool bend);

inline BarCase bar_case(bool bend, const std::string& file = "edit/bar.ply", int subdivisions = 0) {
  Mesh m = load(file);
  for (int k = 0; k < subdivisions; ++k) m = midpoint_subdivide(m);
  return bar_case_of(std::move(m), bend);
}

// The ideal bend or twist of a bar case, for reference: cross-sections stay rigid, the free part
// (between the fixed and the handle slab) bends along a circular arc by 90° / twists uniformly by
// 150°, the parts beyond it move rigidly. Its local rigidity error is the bending / torsion strain
// of the bar itself, which no deformation with these end conditions avoids.
inline Eigen::MatrixXd ideal_bar_deformation(const Eigen::MatrixXd& V, bool bend) {
  const int ax = long_axis(V), up = (ax + 1) % 3, side = (ax + 2) % 3;
  const double lo = V.col(ax).minCoeff(), hi = V.col(ax).maxCoeff();
  const double s0 = lo + 0.1 * (hi - lo), s1 = hi - 0.1 * (hi - lo);
  const Eigen::RowVector3d mid = 0.5 * (V.colwise().minCoeff() + V.colwise().maxCoeff());
  Eigen::MatrixXd out = V;
  for (int i = 0; i < V.rows(); ++i) {
    const double s = V(i, ax), u = V(i, up) - mid[up], w = V(i, side) - mid[side];
    const double t = std::clamp((s - s0) / (s1 - s0), 0.0, 1.0);
    Eigen::Vector3d e_ax = Eigen::Vector3d::Zero(), e_up = e_ax, e_side = e_ax, p;
    e_ax[ax] = 1;
    e_up[up] = 1;
    e_side[side] = 1;
    const Eigen::Vector3d base = mid.transpose() + (s0 - mid[ax]) * e_ax;  // centre line at s0
    if (s <= s0) continue;
    if (bend) {
      const double R = (s1 - s0) / (M_PI / 2), phi = t * M_PI / 2;
      const Eigen::Vector3d C = base + R * e_up;
      const Eigen::Vector3d P = C + R * (std::sin(phi) * e_ax - std::cos(phi) * e_up);
      const Eigen::Vector3d T = std::cos(phi) * e_ax + std::sin(phi) * e_up;
      const Eigen::Vector3d N = std::cos(phi) * e_up - std::sin(phi) * e_ax;
      p = P + std::max(0.0, s - s1) * T + u * N + w * e_side;
    } else {
      const double a = t * 150.0 * M_PI / 180.0;
      p = base + (s - s0) * e_ax + (std::cos(a) * u - std::sin(a) * w) * e_up + (std::sin(a) * u + std::cos(a) * w) * e_side;
    }
    out.row(i) = p.transpose();
  }
  return out;
}

inline BarCase bar_case_of(Mesh mesh, bool bend) {
  BarCase b;
  b.mesh = std::move(mesh);
  const Eigen::MatrixXd& V = b.mesh.V;
  const int ax = long_axis(V);
  b.region.fixed = slab(V, ax, 0.1, false);
  b.region.handles = {slab(V, ax, 0.1, true)};
  Eigen::Vector3d c0 = Eigen::Vector3d::Zero(), ch = Eigen::Vector3d::Zero();
  for (int v : b.region.fixed) c0 += V.row(v).transpose();
  for (int v : b.region.handles[0]) ch += V.row(v).transpose();
  c0 /= b.region.fixed.size();
  ch /= b.region.handles[0].size();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis[ax] = 1;
  if (!bend) {
    b.transform = HandleTransform::similarity(Eigen::Vector3d::Zero(), axis, 150.0 * M_PI / 180.0, ch);
    return b;
  }
  // Quarter circle of the same length in the plane of the long axis and the next axis.
  const int up = (ax + 1) % 3;
  Eigen::Vector3d e_up = Eigen::Vector3d::Zero();
  e_up[up] = 1;
  const double L = (ch - c0).norm(), rho = L / (M_PI / 2);
  const Eigen::Vector3d target = c0 + rho * axis + rho * e_up;
  const Eigen::Vector3d rot_axis = axis.cross(e_up);
  b.transform = HandleTransform::similarity(target - ch, rot_axis, M_PI / 2, ch);
  return b;
}

// Paper Fig. 3: a planar irregular triangulation. A jittered (n+1)×(n+1) grid in the z = 0 plane
// with pseudo-random diagonals (fixed LCG seed), side 1:
//   +--+--+
//   |\ | /|    every vertex is coplanar with its neighbours → all are degenerate (Sec. 3.3);
//   +--+--+    corners with one triangle have valence 2 (widened stencil).
inline Mesh planar_patch(int n) {
  Mesh m;
  m.V.resize((n + 1) * (n + 1), 3);
  unsigned state = 12345u;
  auto rnd = [&]() {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0;
  };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = i / double(n), y = j / double(n);
      if (i > 0 && i < n) x += (rnd() - 0.5) * 0.5 / n;
      if (j > 0 && j < n) y += (rnd() - 0.5) * 0.5 / n;
      m.V.row(j * (n + 1) + i) << x, y, 0.0;
    }
  m.F.resize(2 * n * n, 3);
  int f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      if (rnd() < 0.5) {
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << a, d, c;
      } else {
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << b, d, c;
      }
    }
  return m;
}

// Distance of V.row(i) from the least-squares plane of its neighbours.
inline double plane_distance(const Eigen::MatrixXd& V, int i, const std::vector<int>& ring) {
  Eigen::MatrixXd P(ring.size(), 3);
  for (size_t k = 0; k < ring.size(); ++k) P.row(static_cast<Eigen::Index>(k)) = V.row(ring[k]);
  const Eigen::RowVector3d c = P.colwise().mean();
  const Eigen::MatrixXd Q = P.rowwise() - c;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(Q.transpose() * Q);
  return std::abs((V.row(i) - c).dot(es.eigenvectors().col(0).transpose()));
}

inline double quantile(Eigen::VectorXd v, double q) {
  std::sort(v.data(), v.data() + v.size());
  return v[static_cast<Eigen::Index>(q * (v.size() - 1))];
}


// The human_woman arm (T-pose, +x side): ROI = the arm beyond 35% of the half span, handle = the
// hand beyond 90%; the rest of the body is outside the ROI (fixed).
struct LimbCase {
  Mesh mesh;
  EditRegion region;
  std::vector<int> free;  // ROI minus handle
  double height = 0;
};
inline LimbCase limb_case(const std::string& file = "anim/human_woman.ply") {
  LimbCase c;
  c.mesh = load(file);
  const Eigen::MatrixXd& V = c.mesh.V;
  const double xmin = V.col(0).minCoeff(), xmax = V.col(0).maxCoeff();
  const double xc = 0.5 * (xmin + xmax), half = 0.5 * (xmax - xmin);
  std::vector<int> hand, roi;
  for (int i = 0; i < V.rows(); ++i) {
    const double t = (V(i, 0) - xc) / half;
    if (t > 0.9) hand.push_back(i);
    if (t > 0.35) roi.push_back(i);
    if (t > 0.35 && t <= 0.9) c.free.push_back(i);
  }
  c.region.handles = {hand};
  c.region.roi = roi;
  c.height = V.col(1).maxCoeff() - V.col(1).minCoeff();
  return c;
}

}  // namespace mm::edit_test
