#pragma once
// Inline sin/cos and atan2 for latency-bound hot paths (the closed-form landmark solvers;
// docs/performance.md "Targets and measured figures").
//
// sincos_fast: sin and cos of one angle together, inline, without libm's call, dispatch and exception-flag
// handling: about 45 instructions against ~120 for glibc's sincos (callgrind at commit 14890d4; the three
// bearings' sincos were a quarter of a closed-form landmark solve). Accuracy, measured against
// long-double sinl/cosl on 4e6 random arguments: at most 1.6 ulp for |x| <= 40, 2.3 ulp for
// |x| <= 1e5 (glibc: 0.52), i.e. the last bit or two may differ from libm's; tests/core_test.cpp
// checks 4 ulp. Larger |x| (and inf, NaN) go to std::sin/cos. The sign of sin(-0.0) is not kept.
//
// Method (textbook, Cody & Waite): x = n pi/2 + r with n the nearest integer to x 2/pi and
// |r| <= pi/4; pi/2 split into three parts (33 + 33 + 53 bits) so that n * part is exact for
// |n| < 2^20 and r keeps ~100 bits of pi/2; then polynomials of degree 13 (sin) and 14 (cos) in r;
// finally the quadrant n mod 4 swaps and negates the two, branch-free (products with a 0/+-1 table).
#include <cmath>
#include <cstdint>

namespace omniloc {

inline void sincos_fast(double x, double& s, double& c) {
  if (!(std::fabs(x) <= 1e5)) {  // also inf and NaN
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
  constexpr double kPio2a = 0x1.921fb54400000p+0;   // pi/2, first 33 bits
  constexpr double kPio2b = 0x1.0b4611a600000p-34;  // next 33 bits
  constexpr double kPio2c = 0x1.3198a2e037073p-69;  // the rest, rounded
  constexpr double kRound = 0x1.8p52;               // adding and subtracting it rounds to an integer
  const double n = (x * kTwoOverPi + kRound) - kRound;
  const double r = ((x - n * kPio2a) - n * kPio2b) - n * kPio2c;
  const double z = r * r, z2 = z * z, z4 = z2 * z2;
  // sin r = r + r^3 P(z), cos r = 1 - z / 2 + z^2 Q(z), z = r^2: P and Q of degree 5, Chebyshev fits on
  // [0, (pi/4)^2] (mpmath.chebyfit, 50 digits; max error of P 2e-17, of Q 1.3e-18, i.e. 0.13 and
  // 0.01 ulp of the result at |r| = pi/4), evaluated by Estrin's scheme (three independent pairs)
  // for a short dependency chain: the solvers are latency-bound.
  const double ps = (-0x1.5555555555555p-3 + z * 0x1.1111111110bb2p-7) +
                    z2 * (-0x1.a01a019e83816p-13 + z * 0x1.71de379654304p-19) +
                    z4 * (-0x1.ae600aca92c64p-26 + z * 0x1.5e0b05bff20f2p-33);
  const double pc = (0x1.5555555555555p-5 + z * -0x1.6c16c16c16967p-10) +
                    z2 * (0x1.a01a019f4e9b4p-16 + z * -0x1.27e4fa17bf139p-22) +
                    z4 * (0x1.1eeb68cd22f56p-29 + z * -0x1.907d8f29fe831p-37);
  const double sr = r + r * z * ps;
  const double cr = (1.0 - 0.5 * z) + z * z * pc;
  // Quadrant q = n mod 4: (sin, cos) = (sr, cr), (cr, -sr), (-sr, -cr), (-cr, sr), as products with
  // 0 and +-1 from a table (exact; the index is known long before the polynomials, so the loads
  // cost no latency, and there is no branch or integer round trip).
  static constexpr double kQ[4][4] = {{1, 0, 1, 0}, {0, 1, 0, -1}, {-1, 0, -1, 0}, {0, -1, 0, 1}};
  const double* m = kQ[static_cast<std::uint64_t>(static_cast<std::int64_t>(n)) & 3u];
  s = sr * m[0] + cr * m[1];
  c = cr * m[2] + sr * m[3];
}

/// atan2(y, x) in [-pi, pi], within a few ulp of libm's (measured against long-double atan2l on 4e6
/// random points: see tests/core_test.cpp, which checks 4 ulp), the octant selections written as
/// arithmetic (GCC 12 still compiles the max/min choice below to one branch; forcing maxsd/minsd
/// together with other bit-selects measured slower in the solvers): glibc's atan2 branches on the
/// octant, which is data for a heading, and costs ~135 instructions.
/// Zeros, infinities and NaN go to std::atan2 (the same results as libm there).
///
/// Method (textbook): with mx = max(|x|, |y|), mn = min(|x|, |y|), atan(mn / mx) in [0, pi/4] is
/// taken as atan(t) with t = mn / mx when mn <= tan(pi/8) mx, else as
/// pi/4 + atan(t) with t = (mn - mx) / (mn + mx) (atan's addition formula), so |t| <= tan(pi/8)
/// with one division; atan(t) = t + t^3 R(t^2), R of degree 10, a Chebyshev fit on
/// [0, tan(pi/8)^2] (mpmath.chebyfit, 50 digits; max error 3.2e-17, 0.006 ulp of the result),
/// Estrin's scheme. Then the octant: pi/2 - a when |y| > |x|, pi - a when x < 0, the sign of y.
inline double atan2_fast(double y, double x) {
  const double ax = std::fabs(x), ay = std::fabs(y);
  const double mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  if (!(mn > 0.0) || !(mx < 1e300)) return std::atan2(y, x);  // zeros, huge, inf, NaN
  constexpr double kTanPi8 = 0x1.a827999fcef32p-2;  // tan(pi/8)
  constexpr double kPio4 = 0x1.921fb54442d18p-1, kPio2 = 0x1.921fb54442d18p+0, kPi = 0x1.921fb54442d18p+1;
  // 0 or 1 as doubles, so that the selections below are arithmetic, not branches.
  const double f8 = static_cast<double>(mn > kTanPi8 * mx);
  const double t = (mn - f8 * mx) / (mx + f8 * mn);
  const double z = t * t, z2 = z * z, z4 = z2 * z2, z8 = z4 * z4;
  const double q0 = (-0x1.5555555555555p-2 + z * 0x1.999999999934ap-3) + z2 * (-0x1.24924924360cbp-3 + z * 0x1.c71c7185314cbp-4);
  const double q1 = (-0x1.745d0b26b83e7p-4 + z * 0x1.3b1262d95579ep-4) + z2 * (-0x1.10fa75382537fp-4 + z * 0x1.dfe61e80903d2p-5);
  const double q2 = (-0x1.a098bb6ba4941p-5 + z * 0x1.41603647c7a7cp-5) + z2 * -0x1.3a2b7a07caea9p-6;
  const double rz = (q0 + z4 * q1) + z8 * q2;
  double a = f8 * kPio4 + (t + t * z * rz);  // atan(mn / mx) in [0, pi/4]
  const double fs = static_cast<double>(ay > ax);
  a = fs * kPio2 + (1.0 - 2.0 * fs) * a;  // atan(|y| / |x|)
  const double fx = static_cast<double>(std::signbit(x));
  a = fx * kPi + (1.0 - 2.0 * fx) * a;
  return std::copysign(a, y);
}

}  // namespace omniloc
