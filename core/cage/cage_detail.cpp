#include "cage/cage_detail.h"

#include <algorithm>

namespace mm::cage_detail {

double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Voronoi-region walk of Ericson 5.1.5; returns |p − closest|².
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return dot(ap, ap);
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return dot(bp, bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    const Vec3 q = a + v * ab;
    return dot(p - q, p - q);
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return dot(cp, cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    const Vec3 q = a + w * ac;
    return dot(p - q, p - q);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    const Vec3 q = b + w * (c - b);
    return dot(p - q, p - q);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return std::min({dot(ap, ap), dot(bp, bp), dot(cp, cp)});
  const double v = vb / denom, w = vc / denom;
  const Vec3 q = a + v * ab + w * ac;
  return dot(p - q, p - q);
}

namespace {

// Signed volume (×6) of tetrahedron (a, b, c, d).
double cage_orient3(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return dot(cross(b - a, c - a), d - a);
}

double cage_orient2(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

// 2D segment (p, q) against triangle (a, b, c) after dropping the coordinate `drop`.
bool cage_segment_triangle_2d(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                              const Vec3& c, int drop) {
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  const double P[2] = {p[u], p[v]}, Q[2] = {q[u], q[v]};
  const double T[3][2] = {{a[u], a[v]}, {b[u], b[v]}, {c[u], c[v]}};
  const double area = cage_orient2(T[0][0], T[0][1], T[1][0], T[1][1], T[2][0], T[2][1]);
  auto inside = [&](const double* X) {
    double s[3];
    for (int e = 0; e < 3; ++e)
      s[e] = cage_orient2(T[e][0], T[e][1], T[(e + 1) % 3][0], T[(e + 1) % 3][1], X[0], X[1]) *
             (area >= 0 ? 1 : -1);
    return s[0] >= 0 && s[1] >= 0 && s[2] >= 0;
  };
  if (inside(P) || inside(Q)) return true;
  for (int e = 0; e < 3; ++e) {
    const double* A = T[e];
    const double* B = T[(e + 1) % 3];
    const double o1 = cage_orient2(P[0], P[1], Q[0], Q[1], A[0], A[1]);
    const double o2 = cage_orient2(P[0], P[1], Q[0], Q[1], B[0], B[1]);
    const double o3 = cage_orient2(A[0], A[1], B[0], B[1], P[0], P[1]);
    const double o4 = cage_orient2(A[0], A[1], B[0], B[1], Q[0], Q[1]);
    if (((o1 <= 0 && o2 >= 0) || (o1 >= 0 && o2 <= 0)) && ((o3 <= 0 && o4 >= 0) || (o3 >= 0 && o4 <= 0)))
      return true;
  }
  return false;
}

// Closed segment (p, q) against closed triangle (a, b, c). Exact sign tests on doubles; a
// zero counts as touching, which makes the self-intersection check err on the safe side.
bool cage_segment_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double dp = cage_orient3(a, b, c, p), dq = cage_orient3(a, b, c, q);
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0)) return false;
  if (dp == 0 && dq == 0) {
    const Vec3 n = cross(b - a, c - a);
    const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
    const int drop = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    return cage_segment_triangle_2d(p, q, a, b, c, drop);
  }
  const double s1 = cage_orient3(p, q, a, b), s2 = cage_orient3(p, q, b, c), s3 = cage_orient3(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

}  // namespace

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2) {
  // Two non-coplanar triangles meet iff an edge of one crosses the other: the endpoints of
  // their intersection segment lie on triangle edges.
  const Vec3 A[3] = {a0, a1, a2}, B[3] = {b0, b1, b2};
  for (int e = 0; e < 3; ++e) {
    if (cage_segment_triangle(A[e], A[(e + 1) % 3], b0, b1, b2)) return true;
    if (cage_segment_triangle(B[e], B[(e + 1) % 3], a0, a1, a2)) return true;
  }
  return false;
}

}  // namespace mm::cage_detail
