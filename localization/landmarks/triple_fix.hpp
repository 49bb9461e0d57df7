#pragma once
// Internal to localization/landmarks: the parts every three-landmark closed form shares, inline so
// that each solver's hot path is one function without calls, heap allocations or dynamic Eigen types
// (docs/performance.md "Targets and measured figures"). Same tests and same results as check_triple + finish_fix (landmark_fix.hpp); the
// refusal reasons are produced by those functions, off the hot path, when a test fails.
#include <algorithm>
#include <cmath>
#include <span>

#include "core/angles.hpp"
#include "core/fast_trig.hpp"
#include "localization/landmarks/fix.hpp"

namespace omniloc::landmarks::detail {

/// Branch-light form of check_triple for the common case: true when obs has exactly 3 finite
/// observations, no landmark twice and the landmarks not collinear; then far2 = the largest squared
/// landmark distance (landmark_scale squared). The same tests, in the same arithmetic, as
/// check_input; when it returns false, check_triple(obs) gives the reason.
inline bool triple_ok(std::span<const BearingObs> obs, double& far2) {
  if (obs.size() != 3) return false;
  const Eigen::Vector2d& A = obs[0].landmark;
  const Eigen::Vector2d& B = obs[1].landmark;
  const Eigen::Vector2d& C = obs[2].landmark;
  // v - v is 0 for a finite v and NaN for inf or NaN, so the sum is 0 exactly when all nine are finite.
  const double z = (A.x() - A.x()) + (A.y() - A.y()) + (B.x() - B.x()) + (B.y() - B.y()) + (C.x() - C.x()) +
                   (C.y() - C.y()) + (obs[0].bearing - obs[0].bearing) + (obs[1].bearing - obs[1].bearing) +
                   (obs[2].bearing - obs[2].bearing);
  // Pairs in check_input's order (0, 1), (0, 2), (1, 2); the farthest is the first largest.
  const double d01 = (A - B).squaredNorm(), d02 = (A - C).squaredNorm(), d12 = (B - C).squaredNorm();
  const double near2 = std::min(d01, std::min(d02, d12));
  // Collinearity as check_input: the third landmark's cross product with the farthest pair (the
  // pair's own two terms are exactly 0).
  double off;
  if (d01 >= d02 && d01 >= d12) {
    far2 = d01;
    off = (B.x() - A.x()) * (C.y() - A.y()) - (B.y() - A.y()) * (C.x() - A.x());
  } else if (d02 >= d12) {
    far2 = d02;
    off = (C.x() - A.x()) * (B.y() - A.y()) - (C.y() - A.y()) * (B.x() - A.x());
  } else {
    far2 = d12;
    off = (C.x() - B.x()) * (A.y() - B.y()) - (C.y() - B.y()) * (A.x() - B.x());
  }
  return z == 0.0 && !(near2 < kSameLandmark * kSameLandmark) && !(std::fabs(off) <= kSingularTol * far2);
}

/// Reliability (Fix::reliability) of three bearings at a position whose landmark offsets are
/// d_i = L_i - P, with r2_i = |d_i|^2 > 0. J has the rows (g_i, -1), g_i = (dy, -dx) / r2 the
/// bearing's gradient in (x, y). Subtracting the first row from the others eliminates the heading:
/// with u = g2 - g1, v = g3 - g1, the (x, y) rows of J^-1 are M^-1 E, M = [u; v],
/// E = [-1 1 0; -1 0 1], and the squared norm of M^-1 E (the trace of the position block of
/// J^-1 J^-T) works out to (|g2 - g1|^2 + |g3 - g1|^2 + |g3 - g2|^2) / det(M)^2, det(M) = +-det(J).
/// So reliability = |det(M)| / sqrt(sum of the three squared gradient differences): one division
/// and one square root instead of a general 3 x 3 inverse. 0 when singular.
inline double triple_reliability(const Eigen::Vector2d d[3], const double r2[3]) {
  const double i0 = 1.0 / r2[0], i1 = 1.0 / r2[1], i2 = 1.0 / r2[2];
  const double gx0 = d[0].y() * i0, gy0 = -d[0].x() * i0;
  const double gx1 = d[1].y() * i1, gy1 = -d[1].x() * i1;
  const double gx2 = d[2].y() * i2, gy2 = -d[2].x() * i2;
  const double ux = gx1 - gx0, uy = gy1 - gy0;
  const double vx = gx2 - gx0, vy = gy2 - gy0;
  const double wx = gx2 - gx1, wy = gy2 - gy1;
  const double det = ux * vy - uy * vx;
  const double sum = ux * ux + uy * uy + vx * vx + vy * vy + wx * wx + wy * wy;
  const double rel = std::fabs(det) / std::sqrt(sum);
  return rel > 0.0 && std::isfinite(rel) ? rel : 0.0;
}

/// finish_fix for three observations; c[i], s[i] = (cos, sin)(bearing_i - b0), i.e. the bearings
/// rotated by -b0 (the solvers pass b0 = bearing_0 and so need no sincos of bearing_0 itself;
/// finish_fix passes b0 = 0). scale2 = scale^2 (far2 of triple_ok). Same checks and reasons as
/// finish_fix; reliability by triple_reliability.
inline Fix finish_triple(std::span<const BearingObs> obs, const double c[3], const double s[3], double b0,
                         const Eigen::Vector2d& P, double scale2) {
  Eigen::Vector2d d[3];
  double r2[3];
  double sx = 0.0, sy = 0.0;
  bool at_landmark = false;
  for (int i = 0; i < 3; ++i) {
    d[i] = obs[static_cast<std::size_t>(i)].landmark - P;
    r2[i] = d[i].squaredNorm();
    at_landmark |= r2[i] < kSameLandmark * kSameLandmark;
    // heading_from_bearings: the offset rotated by -bearing, summed (distance-weighted circular
    // mean); here rotated by -(bearing - b0), so the sum's angle is the heading + b0.
    sx += c[i] * d[i].x() + s[i] * d[i].y();
    sy += c[i] * d[i].y() - s[i] * d[i].x();
  }
  if (!std::isfinite(P.x()) || !std::isfinite(P.y()))
    return no_fix("numerical failure: non-finite position (singular geometry)");
  if (at_landmark) return no_fix("robot at a landmark (its bearing is undefined; a point of the singular circle)");
  if (!(sx * sx + sy * sy > 0.0) || !std::isfinite(sx) || !std::isfinite(sy))
    return no_fix("heading undefined at the computed position");
  const double rel = triple_reliability(d, r2);
  if (!(rel * rel * scale2 >= kSingularTol * kSingularTol)) return no_fix("robot on the circle through the three landmarks (singular geometry)");
  Fix f;
  f.ok = true;
  f.pose.x = P.x();
  f.pose.y = P.y();
  // Heading = atan2(sum) - b0, wrapped to Pose2's (-pi, pi] without fmod: subtract the nearest
  // multiple of 2 pi (2 pi in two parts, so that k 2 pi is exact to ~1e-25 rad for |k| < 2^20), then
  // fix the half-open boundary (the rounding may leave t a few ulp outside [-pi, pi]).
  // atan2_fast: branch-free, within ~2 ulp of libm's.
  constexpr double kTwoPiHi = 0x1.921fb544p+2;           // 2 pi, first 33 bits (k kTwoPiHi exact)
  constexpr double kTwoPiLo = 0x1.0b4611a626331p-32;     // 2 pi - kTwoPiHi, rounded
  constexpr double kRound = 0x1.8p52;
  double t = atan2_fast(sy, sx) - b0;
  const double k = (t * (1.0 / kTwoPi) + kRound) - kRound;
  t = (t - k * kTwoPiHi) - k * kTwoPiLo;
  if (t <= -kPi) t += kTwoPi;
  if (t > kPi) t -= kTwoPi;
  f.pose.theta = t;
  f.reliability = rel;
  return f;
}

}  // namespace omniloc::landmarks::detail
