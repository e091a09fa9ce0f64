// Closest point on a triangle (Ericson, Real-Time Collision Detection 5.1.5: walk of the
// Voronoi regions of the corners, edges and face). One algorithm for every 3-vector type:
// Eigen::Vector3d (spatial/triangle_bvh) and the plain scalar cage_detail::Vec3 (core/cage keeps
// its arithmetic out of Eigen so that native and wasm give the same bits); each type keeps its
// own arithmetic, so both get the bits they had before.
#pragma once

#include <cmath>

namespace mm {

// Closest point to p on triangle (a, b, c). Vec needs +, − and double·Vec; dot(x, y) is its dot
// product. Writes the barycentric weights of the result to bary[0..2] when bary is not null.
// A degenerate triangle (no face region) gives the nearest corner.
template <class Vec, class Dot>
Vec closest_point_on_triangle_t(const Vec& p, const Vec& a, const Vec& b, const Vec& c, Dot dot, double* bary) {
  auto set = [bary](double u, double v, double w) {
    if (bary) bary[0] = u, bary[1] = v, bary[2] = w;
  };
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return set(1, 0, 0), a;  // corner a
  const Vec bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return set(0, 1, 0), b;  // corner b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge ab
    const double v = d1 / (d1 - d3);
    set(1 - v, v, 0);
    return a + v * ab;
  }
  const Vec cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return set(0, 0, 1), c;  // corner c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge ac
    const double w = d2 / (d2 - d6);
    set(1 - w, 0, w);
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {  // edge bc
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    set(0, 1 - w, w);
    return b + w * (c - b);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) {  // degenerate triangle: the nearest corner
    const double da = dot(ap, ap), db = dot(bp, bp), dc = dot(cp, cp);
    if (da <= db && da <= dc) return set(1, 0, 0), a;
    if (db <= dc) return set(0, 1, 0), b;
    return set(0, 0, 1), c;
  }
  const double v = vb / denom, w = vc / denom;  // face interior
  set(1 - v - w, v, w);
  return a + v * ab + w * ac;
}

}  // namespace mm
