#include "spatial/quadric.h"

#include <cmath>

namespace mm {

bool Quadric::minimiser(double p[3]) const {
  // Cofactors of the symmetric 3x3 part: A⁻¹ = adj(A) / det A.
  const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22, c02 = a01 * a12 - a02 * a11;
  const double det = a00 * c00 + a01 * c01 + a02 * c02;
  const double tr = (a00 + a11 + a22) / 3;
  if (!(tr > 0) || !(std::abs(det) > 1e-6 * tr * tr * tr)) return false;
  const double c11 = a00 * a22 - a02 * a02, c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
  const double inv = 1.0 / det;
  p[0] = -(c00 * b0 + c01 * b1 + c02 * b2) * inv;
  p[1] = -(c01 * b0 + c11 * b1 + c12 * b2) * inv;
  p[2] = -(c02 * b0 + c12 * b1 + c22 * b2) * inv;
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

}  // namespace mm
