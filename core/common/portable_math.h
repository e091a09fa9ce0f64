// Elementary functions that give the same bits in every build, inline. Emscripten's C library
// is musl, whose math functions are out-of-line calls with branches (asin ~3× glibc's time in
// wasm); glibc rounds some results differently in the last place. The functions here use only
// + − × ÷ and √ (correctly rounded everywhere; no fused multiply-add on our targets) and follow
// the classic fdlibm algorithms with their published minimax coefficients (Sun Microsystems'
// fdlibm 5.3, e_asin.c), which musl uses too: in wasm they return musl's bits, so a hot loop can
// use them there without moving any result, and vectorise. Natively they are within one unit in
// the last place of glibc's; callers whose results must keep their native bits (the automatic
// transfer amplifies last-bit changes) call the C library there.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace mm {

namespace portable_detail {

// R(z) = (asin(x) − x) / x³ as a rational minimax approximation in z = x², |x| ≤ 0.5. T is
// double or a SIMD vector of doubles (lane by lane, the same bits per lane).
template <class T>
inline T asin_ratio(T z) {
  const T p = z * (1.66666666666666657415e-01 +
                        z * (-3.25565818622400915405e-01 +
                             z * (2.01212532134862925881e-01 +
                                  z * (-4.00555345006794114027e-02 +
                                       z * (7.91534994289814532176e-04 + z * 3.47933107596021167570e-05)))));
  const T q = 1.0 + z * (-2.40339491173441421878e+00 +
                              z * (2.02094576023350569471e+00 +
                                   z * (-6.88283971605453293030e-01 + z * 7.70381505559019352791e-02)));
  return p / q;
}

constexpr double kHalfPiHi = 1.57079632679489655800e+00;  // π/2 rounded to double
constexpr double kHalfPiLo = 6.12323399573676603587e-17;  // π/2 − kHalfPiHi

}  // namespace portable_detail

// asin(x) for |x| < 0.5 (branch-free: vectorises in loops; T as above). x + x·R(x²) also
// returns x itself below 2⁻²⁶, as fdlibm's separate branch does.
template <class T>
inline T asin_below_half(T x) {
  return x + x * portable_detail::asin_ratio(x * x);
}

// asin(x) for any x: NaN outside [−1, 1], ±π/2 at ±1.
inline double portable_asin(double x) {
  using namespace portable_detail;
  const double ax = std::fabs(x);
  if (!(ax <= 1.0)) return std::nan("");
  if (ax < 0.5) return asin_below_half(x);
  if (ax == 1.0) return x * kHalfPiHi;
  // asin(x) = π/2 − 2 asin(√z) with z = (1 − x)/2 ≤ 1/4.
  const double z = (1.0 - ax) * 0.5;
  const double s = std::sqrt(z);
  const double r = asin_ratio(z);
  uint64_t ax_bits;
  std::memcpy(&ax_bits, &ax, sizeof ax_bits);
  double y;
  if ((ax_bits >> 32) >= 0x3fef3333u) {  // ax ≥ 0.97499990463 (fdlibm's test on the high word)
    y = kHalfPiHi - (2.0 * (s + s * r) - kHalfPiLo);
  } else {
    // s = f + c with f = s's leading 32 bits, so that 2f is exact and c carries the rest.
    uint64_t bits;
    std::memcpy(&bits, &s, sizeof bits);
    bits &= 0xffffffff00000000ull;
    double f;
    std::memcpy(&f, &bits, sizeof f);
    const double c = (z - f * f) / (s + f);
    y = 0.5 * kHalfPiHi - (2.0 * s * r - (kHalfPiLo - 2.0 * c) - (0.5 * kHalfPiHi - 2.0 * f));
  }
  return x < 0 ? -y : y;
}

}  // namespace mm
