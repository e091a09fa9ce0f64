// Plane quadric of Garland & Heckbert 1997 (quadric error metric): Q(p) = Σ wᵢ·(nᵢ·p − dᵢ)², the
// weighted sum of squared distances of p to a set of planes, stored as a symmetric 4x4 (10
// numbers) plus the total weight. Quadrics of two vertices merge by addition, which is what edge
// collapse simplification (cage/hull_decimation) needs.
//
// Plain scalar arithmetic in a fixed order (no Eigen): callers that take discrete decisions on
// these values (collapse order) get the same bits natively and in wasm (see cage/cage_detail.h).
#pragma once

namespace mm {

struct Quadric {
  // Upper triangle of the 3x3 part A = Σ w n nᵀ, the linear part b = −Σ w d n, the constant
  // c = Σ w d², and the total weight (the area, for area-weighted planes).
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, b0 = 0, b1 = 0, b2 = 0, c = 0, area = 0;

  // Adds the plane n·p = d (n a unit normal) with weight w.
  void add_plane(double nx, double ny, double nz, double d, double w) {
    a00 += w * nx * nx; a01 += w * nx * ny; a02 += w * nx * nz;
    a11 += w * ny * ny; a12 += w * ny * nz; a22 += w * nz * nz;
    b0 -= w * nx * d; b1 -= w * ny * d; b2 -= w * nz * d;
    c += w * d * d;
    area += w;
  }

  // Q += q (the merged vertex of an edge collapse).
  void add(const Quadric& q) {
    a00 += q.a00; a01 += q.a01; a02 += q.a02; a11 += q.a11; a12 += q.a12; a22 += q.a22;
    b0 += q.b0; b1 += q.b1; b2 += q.b2; c += q.c; area += q.area;
  }

  // Q(p) = pᵀA p + 2 bᵀp + c (≥ 0 up to rounding).
  double eval(double x, double y, double z) const {
    return a00 * x * x + 2 * a01 * x * y + 2 * a02 * x * z + a11 * y * y + 2 * a12 * y * z + a22 * z * z +
           2 * (b0 * x + b1 * y + b2 * z) + c;
  }

  // The minimiser p = −A⁻¹ b, written to p[0..2], when A is well conditioned
  // (|det A| > 1e-6·(tr A / 3)³, tr A > 0) and the result is finite; otherwise false.
  bool minimiser(double p[3]) const;
};

}  // namespace mm
