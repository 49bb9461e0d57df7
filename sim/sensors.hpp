#pragma once
// Robot-side sensors simulated from the world: wheel odometry and an absolute heading sensor
// (compass / MTi). Their readings are what the localization side gets.
#include <string>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/messages.hpp"
#include "core/rng.hpp"

namespace omniloc::sim {

/// Odometry error model. Variance grows with distance travelled (random-walk error, m/sqrt(m)),
/// plus a per-run scale error of the wheel calibration drawn once. Slip comes from the physics:
/// the wheels report the drive's motion even when a contact stopped or pushed the body.
struct OdometryNoise {
  double trans_sigma = 0.0;      ///< m per sqrt(m) travelled, along each robot axis
  double rot_sigma = 0.0;        ///< rad per sqrt(rad) turned
  double rot_per_trans = 0.0;    ///< rad per sqrt(m) travelled (heading drift from driving)
  double scale_sigma = 0.0;      ///< std of the per-run wheel scale error (fraction, e.g. 0.01 = 1 %)
  static OdometryNoise from_json(JsonReader& r, const OdometryNoise& defaults);
  /// The JSON keys (a robot's "odometry", data/noise_profiles.json), ranges and meanings.
  static const ParamList<OdometryNoise>& params();
};

class OdometrySensor {
 public:
  OdometrySensor(const OdometryNoise& noise, Rng rng);
  /// Adds one physics step of wheel motion (robot frame at the step start).
  void accumulate(const Pose2& wheel_step);
  /// The motion since the previous read(), and starts a new interval.
  Odometry read(double t);

 private:
  OdometryNoise noise_;
  Rng rng_;
  double scale_x_ = 1.0, scale_y_ = 1.0, scale_r_ = 1.0;
  Pose2 acc_;
};

/// Heading sensor error model: white noise, a bias that performs a random walk (drift), an
/// optional constant drift rate and a fixed offset (e.g. pi for a compass turned round).
struct HeadingNoise {
  double noise_sigma = 0.0;   ///< rad, white noise per reading
  double bias_walk = 0.0;     ///< rad / sqrt(s), random-walk intensity of the bias
  double drift_rate = 0.0;    ///< rad / s, deterministic drift
  double initial_bias = 0.0;  ///< rad
  double offset = 0.0;        ///< rad, fixed mounting error
  static HeadingNoise from_json(JsonReader& r, const HeadingNoise& defaults);
  /// The JSON keys (a robot's "heading", data/noise_profiles.json), ranges and meanings.
  static const ParamList<HeadingNoise>& params();
};

class HeadingSensor {
 public:
  HeadingSensor(const HeadingNoise& noise, Rng rng);
  /// Advances the bias by dt seconds.
  void advance(double dt);
  HeadingReading read(double t, double true_heading);
  double bias() const { return bias_; }

 private:
  HeadingNoise noise_;
  Rng rng_;
  double bias_;
};

}  // namespace omniloc::sim
