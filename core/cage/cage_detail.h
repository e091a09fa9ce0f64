// Internal helpers of core/cage (not part of the public API): a plain 3-vector with scalar
// arithmetic, and the few geometric predicates the cage builder needs.
//
// Why not Eigen::Vector3d here: Eigen vectorises small fixed-size reductions with SSE2
// natively but not in wasm, which changes the summation order and therefore the last bits.
// The cage builder takes discrete decisions (collapse order, accept/reject) on these values,
// so a 1-ulp difference could give a different cage on the two targets. Plain scalar code in a
// fixed order gives the same bits on both (no FMA contraction on either target).
#pragma once

#include <cmath>

namespace mm::cage_detail {

struct Vec3 {
  double x = 0, y = 0, z = 0;
  Vec3() = default;
  Vec3(double a, double b, double c) : x(a), y(b), z(c) {}
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return n > 0 ? (1.0 / n) * a : Vec3{};
}

// Twice the area vector of triangle (a, b, c): (b − a) × (c − a).
inline Vec3 area_vector(const Vec3& a, const Vec3& b, const Vec3& c) { return cross(b - a, c - a); }

// Squared distance from p to triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// True when the triangles cross properly (an edge of one passes through the interior of the
// other, beyond a relative epsilon). Touching, coplanar contact and zero-area triangles are not
// reported: the test guards the cage against folding into itself, where exact contact is noise.
bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                         const Vec3& b1, const Vec3& b2);

}  // namespace mm::cage_detail
