#pragma once
// Scenario files: everything one run needs (field, timing, seed, robots with start pose, motion
// script and sensor noise, the ball, events, the localizer and its parameters). Parsing validates
// the whole file, including the localizer's and the scripts' parameters, before any work starts;
// every problem is a ConfigError naming its JSON path. Reference: docs/scenario.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "harness/scoring/metrics.hpp"
#include "harness/events.hpp"
#include "harness/localizer_spec.hpp"
#include "sim/occlusion.hpp"
#include "sim/sensors.hpp"
#include "sim/world_state.hpp"
#include "sim/world.hpp"

namespace omniloc::harness {

/// Sensor-noise defaults a scenario starts from (explicit values override them). The named profiles
/// and the argument for each value are data: data/noise_profiles.json (harness/noise_profile.cpp).
struct NoiseProfile {
  std::string name;
  sim::OdometryNoise odometry;
  sim::HeadingNoise heading;
  Json camera;  ///< defaults merged under the scenario's "camera" object
  static NoiseProfile named(const std::string& name, const std::string& path);
  static std::vector<std::string> names();
};

struct RobotConfig {
  sim::RobotSpec spec;
  Json motion;            ///< validated motion-script JSON
  std::string motion_path;
  bool localize = false;  ///< run the localizer on this robot and score it
  bool has_heading_sensor = true;
  sim::OdometryNoise odometry;
  sim::HeadingNoise heading;
};


struct Scenario {
  std::string name;
  std::string description;
  std::string source;        ///< file it came from
  std::uint64_t seed = 1;
  double duration = 30.0;    ///< seconds
  double physics_rate = 200; ///< Hz
  double camera_rate = 30;   ///< Hz
  Field field;
  NoiseProfile noise;
  std::vector<RobotConfig> robots;
  bool has_ball = false;
  Eigen::Vector2d ball_position = Eigen::Vector2d::Zero();
  Eigen::Vector2d ball_velocity = Eigen::Vector2d::Zero();
  std::vector<Event> events;       ///< sorted by time (harness/events.hpp)
  sim::OcclusionMask occlusion;     ///< for the whole run (paper 002 table 1)
  sim::Lighting lighting;           ///< at t = 0
  std::vector<Eigen::Vector2d> sun_velocity;  ///< m/s per sun patch (sun moving slowly)
  Scoring scoring;           ///< recall thresholds (docs/results.md "Coverage and recall")
  LocalizerSpec localizer;   ///< {"type": ..., params} and where it was given
  Json camera;               ///< camera configuration (profile defaults merged)
  Json vision;               ///< vision front-end configuration (calibration, colour table, scan lines)
  Json effective;            ///< every value read, defaults filled in: saved as config.json
  Json input;                ///< the JSON as given (a recording keeps it, so a replay parses the same scenario)

  const RobotConfig* robot(int id) const;
  /// Lighting at time t: lamp events applied with their transitions, sun patches moved.
  sim::Lighting lighting_at(double t) const;
  std::vector<int> localized_robots() const;
};

/// Parses and validates; `name` defaults to the file's stem. Throws ConfigError (LocalizerError for
/// the localizer). `localizer`: the one to run instead of the scenario's own "localizer" (replay
/// --localizer, a sweep's localizers), read where it was given; the scenario's own is then not read.
Scenario parse_scenario(const Json& j, const std::string& name, const std::string& source = "", const LocalizerSpec* localizer = nullptr);
/// Reads a scenario file (JSON syntax errors are ConfigErrors too, with line and column).
Scenario load_scenario(const std::string& path);
/// Builds everything the run would build (localizer, scripts) without running: full validation.
void validate_deep(const Scenario& s);

/// The camera latency the scenario declares (its camera's `latency_ms`, in seconds; 0 when none):
/// what LocalizerContext::camera_latency and olp/1's hello.camera.latency_s carry.
double declared_camera_latency(const Scenario& sc);
/// The camera's mirror viewpoint height above the floor (its `mount_height`, metres) and per-frame
/// vibration (its `vibration_deg`, in radians, each of roll and pitch; 0 when none, as for a log not
/// made by omniloc): what LocalizerContext::camera_mount_height / camera_vibration and olp/1's
/// hello.camera.mount_height_m / vibration_rad carry.
double declared_camera_mount_height(const Scenario& sc);
double declared_camera_vibration(const Scenario& sc);

}  // namespace omniloc::harness
