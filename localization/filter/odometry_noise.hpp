#pragma once
// Odometry motion noise, shared by MCL's sampled motion model and the pose Kalman filter's process
// noise (matching, hybrid, grid_global): the robot moves by the odometry increment `delta` (robot
// frame of the previous pose: x forward, y left, metres; theta anticlockwise, radians) plus zero-mean
// Gaussian noise whose standard deviation grows with the motion:
//   sigma_xy    = trans_frac * |(dx, dy)| + floor_xy                        (m, each of x and y)
//   sigma_theta = rot_frac * |dtheta| + rot_per_m * |(dx, dy)| + floor_theta  (rad)
// per frame. The proportional terms are the usual odometry error model (Thrun et al., Probabilistic
// Robotics, 5.4: alpha_1..alpha_4); the floors keep a standing robot's belief from collapsing (a
// particle set without them loses its diversity, a Kalman filter becomes overconfident).
#include <cmath>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/pose2.hpp"
#include "core/rng.hpp"

namespace omniloc::filter {

struct OdometryNoiseParams {
  double trans_frac = 0.0;   ///< of the distance travelled (JSON odo_trans_frac)
  double rot_frac = 0.0;     ///< of the angle turned (odo_rot_frac)
  double rot_per_m = 0.0;    ///< rad per metre travelled (odo_rot_per_m; MCL has no such key, 0 there)
  double floor_xy = 0.0;     ///< m per frame (odo_floor_xy)
  double floor_theta = 0.0;  ///< rad per frame (odo_floor_theta)

  /// Which JSON keys a localizer accepts. MCL never had odo_rot_per_m; reading it there would add a
  /// key to its effective configuration (config.json), so MCL reads the planar set only.
  enum class Keys { Planar, WithRotPerMetre };
  /// Reads odo_trans_frac, odo_rot_frac, [odo_rot_per_m,] odo_floor_xy, odo_floor_theta, each
  /// defaulting to the field of `defaults`.
  static OdometryNoiseParams from_json(JsonReader& r, const OdometryNoiseParams& defaults, Keys keys);
  static const ParamList<OdometryNoiseParams>& params(Keys keys);
};

/// Standard deviations of one frame's motion noise.
struct OdometrySigmas {
  double xy = 0.0;     ///< m, of each of x and y
  double theta = 0.0;  ///< rad
};

inline OdometrySigmas odometry_sigmas(const Pose2& delta, const OdometryNoiseParams& p) {
  const double dist = std::hypot(delta.x, delta.y);
  return {p.trans_frac * dist + p.floor_xy, p.rot_frac * std::fabs(delta.theta) + p.rot_per_m * dist + p.floor_theta};
}

/// (x + N(0, s.xy), y + N(0, s.xy), theta + N(0, s.theta)): a noisy odometry increment (robot frame)
/// for the sampled motion model, or a pose scattered around a known start (world frame).
/// The draws are taken theta first, then y, then x: the order GCC evaluated the arguments of the
/// one-expression constructor call this replaces, kept so that every run reproduces its numbers.
inline Pose2 perturb(const Pose2& q, const OdometrySigmas& s, Rng& rng) {
  const double nth = rng.normal(0, s.theta);
  const double ny = rng.normal(0, s.xy);
  const double nx = rng.normal(0, s.xy);
  return Pose2(q.x + nx, q.y + ny, q.theta + nth);
}

}  // namespace omniloc::filter
