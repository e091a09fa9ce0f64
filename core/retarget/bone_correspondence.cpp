#include "retarget/bone_correspondence.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace mm {

namespace retarget_detail {

// Minimal rotation taking unit vector a to unit vector b.
Eigen::Matrix3d rotation_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return Eigen::Quaterniond::FromTwoVectors(a, b).toRotationMatrix();
}

}  // namespace retarget_detail

BoneCorrespondence bone_correspondence(const Eigen::MatrixXd& Y, const std::vector<std::pair<int, int>>& bones,
                                       const Eigen::MatrixXd& Jt, const Eigen::MatrixXd& Js,
                                       const TriangleBvh& bvh_t, const TriangleBvh& bvh_s) {
  BoneCorrespondence r;
  const int n = static_cast<int>(Y.rows()), nb = static_cast<int>(bones.size());
  r.X = Y;
  r.bone = Eigen::VectorXi::Constant(n, -1);
  r.u = Eigen::VectorXd::Zero(n);
  if (nb == 0) return r;
  std::vector<Eigen::Matrix3d> Rb(nb);
  for (int b = 0; b < nb; ++b) {
    const Eigen::Vector3d dt = (Jt.row(bones[b].first) - Jt.row(bones[b].second)).transpose();
    const Eigen::Vector3d ds = (Js.row(bones[b].first) - Js.row(bones[b].second)).transpose();
    Rb[b] = retarget_detail::rotation_between(dt.normalized(), ds.normalized());
  }
  std::vector<std::pair<double, int>> order(nb);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d y = Y.row(i).transpose();
    std::vector<double> ub(nb);
    std::vector<Eigen::Vector3d> qb(nb);
    for (int b = 0; b < nb; ++b) {
      const Eigen::Vector3d p = Jt.row(bones[b].second).transpose(), c = Jt.row(bones[b].first).transpose();
      const Eigen::Vector3d d = c - p;
      ub[b] = std::clamp((y - p).dot(d) / std::max(1e-300, d.squaredNorm()), 0.0, 1.0);
      // A clamped point is the joint itself, bit for bit: the bones meeting there then tie
      // exactly and the lower index wins. (p + 1·d is not c in floating point; the last bits
      // decided between the two bones for every y whose nearest bone point is their shared
      // joint, and moving the joints by 1e-9 moved a retargeted Fox → wolf0 frame by 0.37 units.)
      qb[b] = ub[b] <= 0 ? p : ub[b] >= 1 ? c : Eigen::Vector3d(p + ub[b] * d);
      order[b] = {(y - qb[b]).squaredNorm(), b};
    }
    std::sort(order.begin(), order.end());
    // The nearest bone that sees y: the segment bone point → y (stopped just short of y, which
    // lies on the surface) must not cross the surface. Only the 4 nearest are tried.
    int pick = order[0].second;
    for (int k = 0; k < std::min(nb, 4); ++k) {
      const int b = order[k].second;
      const Eigen::Vector3d end = qb[b] + 0.98 * (y - qb[b]);
      if (!bvh_t.segment_hits(qb[b], end)) {
        pick = b;
        break;
      }
    }
    const Eigen::Vector3d o = y - qb[pick];
    const double len = o.norm();
    const Eigen::Vector3d ps = Js.row(bones[pick].second).transpose(), cs = Js.row(bones[pick].first).transpose();
    const Eigen::Vector3d qs = ub[pick] <= 0 ? ps : ub[pick] >= 1 ? cs : Eigen::Vector3d(ps + ub[pick] * (cs - ps));
    r.bone[i] = pick;
    r.u[i] = ub[pick];
    if (len < 1e-12) {
      r.X.row(i) = qs.transpose();
      continue;
    }
    const Eigen::Vector3d dir = Rb[pick] * (o / len);
    // Radii along the direction on both shapes: the point keeps its fraction of the radius.
    // Characters made of interpenetrating parts (KayKit: arms and legs reach into the body) have
    // buried surfaces, so the ray from the bone may cross the surface before it reaches y. The
    // target radius r_t is the crossing nearest to y (y itself: y lies on the target surface);
    // on the source ray we take the crossing nearest to r_t scaled by the ratio of the two first
    // crossings (the bones' thickness ratio). A bone that sees y gets the first crossings on both
    // sides (as before); identical characters get x = y also through buried layers. Choosing by
    // distance, not by counting crossings, keeps the choice stable when a ray grazes an edge
    // (a crossing counted on one platform and missed on another).
    const double step = 1e-6 * len;
    const std::vector<double> ht = bvh_t.ray_crossings(qb[pick], o / len, 4 * len, 16, step);
    const std::vector<double> hs = bvh_s.ray_crossings(qs, dir, 8 * len, 16, step);
    auto nearest = [](const std::vector<double>& h, double target) {
      double best = h[0];
      for (double s : h)
        if (std::abs(s - target) < std::abs(best - target)) best = s;
      return best;
    };
    const double rt = ht.empty() ? -1.0 : nearest(ht, len);
    const double rs = hs.empty() || ht.empty() ? (hs.empty() ? -1.0 : hs[0]) : nearest(hs, rt * hs[0] / ht[0]);
    // y at the same fraction of the radius (≈1: r_t is normally y's own crossing; when the ray
    // slipped through a seam past y it is a neighbouring crossing and the fraction corrects it).
    const double frac = rt > 0 ? len / rt : 1.0;
    const double radius = rs > 0 ? rs : len;
    r.X.row(i) = (qs + dir * frac * radius).transpose();
  }
  return r;
}

}  // namespace mm
