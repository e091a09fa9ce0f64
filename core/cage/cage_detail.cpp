#include "cage/cage_detail.h"

#include <algorithm>

#include "spatial/point_triangle.h"

namespace mm::cage_detail {

double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson 5.1.5 (spatial/point_triangle.h) in scalar Vec3 arithmetic; returns |p − closest|².
  const Vec3 d = p - closest_point_on_triangle_t(
                         p, a, b, c, [](const Vec3& x, const Vec3& y) { return dot(x, y); }, nullptr);
  return dot(d, d);
}

namespace {

// Proper crossing of segment (p, q) through the interior of triangle (a, b, c): the endpoints
// are on opposite sides of the plane by more than a relative epsilon, and the crossing point is
// strictly inside. Touching and coplanar contact are not reported. The offset surface is full
// of exactly coplanar and collinear grid-aligned pieces, where exact sign tests on rounded
// values report contact noise as intersections and would block every collapse nearby.
bool cage_segment_crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = cross(b - a, c - a);
  const double ln = norm(n);
  if (!(ln > 0)) return false;
  const double dp = dot(n, p - a) / ln, dq = dot(n, q - a) / ln;
  const double eps = 1e-10 * (norm(q - p) + norm(b - a) + norm(c - a));
  if (!((dp > eps && dq < -eps) || (dp < -eps && dq > eps))) return false;
  const Vec3 x = p + (dp / (dp - dq)) * (q - p);
  const double wa = dot(n, cross(b - x, c - x)), wb = dot(n, cross(c - x, a - x)), wc = dot(n, cross(a - x, b - x));
  return wa > 0 && wb > 0 && wc > 0;
}

}  // namespace

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2) {
  // Two non-coplanar triangles meet iff an edge of one crosses the other: the endpoints of
  // their intersection segment lie on triangle edges.
  const Vec3 A[3] = {a0, a1, a2}, B[3] = {b0, b1, b2};
  for (int e = 0; e < 3; ++e) {
    if (cage_segment_crosses(A[e], A[(e + 1) % 3], b0, b1, b2)) return true;
    if (cage_segment_crosses(B[e], B[(e + 1) % 3], a0, a1, a2)) return true;
  }
  return false;
}

}  // namespace mm::cage_detail
