#pragma once
// Angle helpers. All angles in radians.
#include <cmath>
#include <numbers>

namespace omniloc {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Wraps an angle to (-pi, pi].
inline double wrap_angle(double a) {
  a = std::fmod(a + kPi, kTwoPi);
  if (a <= 0.0) a += kTwoPi;
  return a - kPi;
}

/// Wraps an angle to [0, 2 pi).
inline double wrap_angle_positive(double a) {
  a = std::fmod(a, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return a;
}

/// Signed smallest difference a - b, in (-pi, pi].
inline double angle_diff(double a, double b) { return wrap_angle(a - b); }

inline constexpr double deg2rad(double d) { return d * kPi / 180.0; }
inline constexpr double rad2deg(double r) { return r * 180.0 / kPi; }

}  // namespace omniloc
