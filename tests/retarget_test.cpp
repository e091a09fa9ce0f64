// Tests of core/retarget (paper 002): MFS kernel derivatives, harmonic map fit, joint matching
// and errors, synthesis, self-retargeting on synthetic and real characters, the LBS baseline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "retarget/harmonic_map.h"
#include "retarget/harmonic_retarget.h"
#include "retarget/joint_set.h"
#include "retarget/lbs_baseline.h"
#include "retarget/mfs_kernel.h"

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

TEST(RetargetHarmonicMap, FitsRigidAndBentTube) {
  Eigen::MatrixXd V;
  Eigen::MatrixXi F;
  tube(0.15, 1.0, 21, 16, &V, &F);
  mm::MfsHarmonicMap map;
  ASSERT_TRUE(map.build(V, F).ok());
  EXPECT_EQ(map.num_singularities(), 260);
  // Identity and a rigid motion are harmonic: reproduced almost exactly on the surface.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::MatrixXd Vr = V * R.transpose();
  Vr.rowwise() += Eigen::RowVector3d(0.3, -0.2, 0.1);
  const Eigen::MatrixXd K = mm::mfs_kernel(V, map.singularities());
  EXPECT_LT(mean_distance(K * map.fit(V), V), 1e-4);
  EXPECT_LT(mean_distance(K * map.fit(Vr), Vr), 1e-4);
  // The Jacobian of the rigid fit at an interior point is R.
  Eigen::MatrixXd x(1, 3);
  x << 0, 0.5, 0;
  const Eigen::Matrix3d J = (mm::mfs_gradient(x, map.singularities()) * map.fit(Vr)).transpose();
  EXPECT_LT((J - R).norm(), 1e-3);
  // A 60° bend is fitted to a fraction of a percent of the length.
  const Eigen::MatrixXd Vb = bend(V, 1.0, M_PI / 3);
  EXPECT_LT(mean_distance(K * map.fit(Vb), Vb), 5e-3);
}
