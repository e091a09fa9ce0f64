#include "cage/cage_containment.h"

#include <algorithm>
#include <cmath>

#include "cage/cage_detail.h"

namespace mm {

namespace containment_detail {

using cage_detail::Vec3;

// Sign of orient2d((u, w), q) in the (y, z) plane under the perturbation q + (ε, ε²).
int perturbed_side(double uy, double uz, double wy, double wz, double qy, double qz) {
  const double o = (wy - uy) * (qz - uz) - (wz - uz) * (qy - uy);
  if (o > 0) return 1;
  if (o < 0) return -1;
  const double e1 = -(wz - uz);
  if (e1 > 0) return 1;
  if (e1 < 0) return -1;
  const double e2 = wy - uy;
  return e2 > 0 ? 1 : (e2 < 0 ? -1 : 0);
}

}  // namespace containment_detail

CageContainment cage_containment(const Eigen::MatrixXd& P, const Eigen::MatrixXd& C,
                                 const Eigen::MatrixXi& CF, double clearance) {
  using containment_detail::Vec3;
  CageContainment out;
  const int np = static_cast<int>(P.rows());
  const int nc = static_cast<int>(C.rows());
  const int nf = static_cast<int>(CF.rows());
  if (nc < 4 || nf < 4) {
    out.status = Status::error(StatusCode::InvalidArgument, "a cage needs at least 4 vertices and 4 faces");
    return out;
  }
  for (int f = 0; f < nf; ++f)
    for (int c = 0; c < 3; ++c)
      if (CF(f, c) < 0 || CF(f, c) >= nc) {
        out.status = Status::error(StatusCode::InvalidArgument,
                                   "cage face " + std::to_string(f) + " has an invalid vertex index");
        return out;
      }
  std::vector<Vec3> cv(nc);
  for (int i = 0; i < nc; ++i) cv[i] = Vec3(C(i, 0), C(i, 1), C(i, 2));
  Vec3 lo = cv[0], hi = cv[0];
  for (const Vec3& p : cv) {
    lo = Vec3(std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z));
    hi = Vec3(std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z));
  }

  // 2D bins over (y, z) for the ray casts along +x.
  const int G = std::clamp(static_cast<int>(std::sqrt(double(nf))), 4, 128);
  const double sy = std::max((hi.y - lo.y) / G, 1e-300), sz = std::max((hi.z - lo.z) / G, 1e-300);
  auto bin = [&](double v, double l, double s) { return std::clamp(static_cast<int>(std::floor((v - l) / s)), 0, G - 1); };
  std::vector<std::vector<int>> columns(static_cast<size_t>(G) * G);
  for (int f = 0; f < nf; ++f) {
    const Vec3 &a = cv[CF(f, 0)], &b = cv[CF(f, 1)], &c = cv[CF(f, 2)];
    const int y0 = bin(std::min({a.y, b.y, c.y}), lo.y, sy), y1 = bin(std::max({a.y, b.y, c.y}), lo.y, sy);
    const int z0 = bin(std::min({a.z, b.z, c.z}), lo.z, sz), z1 = bin(std::max({a.z, b.z, c.z}), lo.z, sz);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) columns[y + static_cast<size_t>(G) * z].push_back(f);
  }

  // 3D bins for the clearance test.
  const double longest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double cs = std::max(clearance, longest / 48.0);
  int dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = static_cast<int>(std::ceil((hi[k] - lo[k]) / cs)) + 1;
  auto cell_of = [&](double v, int k) { return std::clamp(static_cast<int>(std::floor((v - lo[k]) / cs)), 0, dims[k] - 1); };
  std::vector<std::vector<int>> cells(static_cast<size_t>(dims[0]) * dims[1] * dims[2]);
  for (int f = 0; f < nf; ++f) {
    const Vec3 &a = cv[CF(f, 0)], &b = cv[CF(f, 1)], &c = cv[CF(f, 2)];
    int r0[3], r1[3];
    for (int k = 0; k < 3; ++k) {
      r0[k] = cell_of(std::min({a[k], b[k], c[k]}), k);
      r1[k] = cell_of(std::max({a[k], b[k], c[k]}), k);
    }
    for (int z = r0[2]; z <= r1[2]; ++z)
      for (int y = r0[1]; y <= r1[1]; ++y)
        for (int x = r0[0]; x <= r1[0]; ++x)
          cells[x + static_cast<size_t>(dims[0]) * (y + static_cast<size_t>(dims[1]) * z)].push_back(f);
  }
  std::vector<unsigned> seen(nf, 0);
  unsigned query = 0;

  out.winding.setZero(np);
  out.distance.setConstant(np, clearance);
  for (int i = 0; i < np; ++i) {
    const Vec3 q(P(i, 0), P(i, 1), P(i, 2));
    int w = 0;
    if (q.y >= lo.y && q.y <= hi.y && q.z >= lo.z && q.z <= hi.z) {
      for (int f : columns[bin(q.y, lo.y, sy) + static_cast<size_t>(G) * bin(q.z, lo.z, sz)]) {
        const Vec3 &a = cv[CF(f, 0)], &b = cv[CF(f, 1)], &c = cv[CF(f, 2)];
        const Vec3 n = cage_detail::area_vector(a, b, c);
        if (n.x == 0) continue;  // parallel to the (perturbed) ray
        const int o = n.x > 0 ? 1 : -1;
        if (containment_detail::perturbed_side(a.y, a.z, b.y, b.z, q.y, q.z) != o) continue;
        if (containment_detail::perturbed_side(b.y, b.z, c.y, c.z, q.y, q.z) != o) continue;
        if (containment_detail::perturbed_side(c.y, c.z, a.y, a.z, q.y, q.z) != o) continue;
        const double x_hit = a.x - (n.y * (q.y - a.y) + n.z * (q.z - a.z)) / n.x;
        if (x_hit > q.x) w += o;
      }
    }
    out.winding[i] = w;
    if (clearance > 0) {
      ++query;
      double best2 = clearance * clearance;
      int r0[3], r1[3];
      for (int k = 0; k < 3; ++k) {
        r0[k] = cell_of(q[k] - clearance, k);
        r1[k] = cell_of(q[k] + clearance, k);
      }
      for (int z = r0[2]; z <= r1[2]; ++z)
        for (int y = r0[1]; y <= r1[1]; ++y)
          for (int x = r0[0]; x <= r1[0]; ++x)
            for (int f : cells[x + static_cast<size_t>(dims[0]) * (y + static_cast<size_t>(dims[1]) * z)]) {
              if (seen[f] == query) continue;
              seen[f] = query;
              best2 = std::min(best2, cage_detail::point_triangle_distance2(q, cv[CF(f, 0)], cv[CF(f, 1)], cv[CF(f, 2)]));
            }
      out.distance[i] = std::sqrt(best2);
    }
    if (w != 1 || out.distance[i] < clearance) out.not_inside.push_back(i);
  }
  return out;
}

}  // namespace mm
