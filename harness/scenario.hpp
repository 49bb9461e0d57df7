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
#include "sim/occlusion.hpp"
#include "sim/sensors.hpp"
#include "sim/world_state.hpp"
#include "sim/world.hpp"

namespace omniloc::harness {

/// Sensor-noise defaults a scenario starts from (explicit values override them).
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

struct EventConfig {
  double t = 0.0;            ///< seconds
  std::string type;          ///< "teleport", "cover", "kidnap", "occlude", "lights"
  int robot = 0;
  Pose2 pose;                ///< teleport / kidnap target
  bool random_pose = false;  ///< "pose": "random": drawn from the run's seed (stream "events") on the field
  double duration = 0.0;     ///< cover / kidnap / occlude: how long, seconds
  sim::OcclusionMask mask;   ///< occlude
  double level = 1.0;        ///< lights: new global illumination level, or with `lamps` those lamps' new state (0 off, 1 on)
  double transition = 0.0;   ///< lights: seconds to reach it (lamps warming up / dimming)
  std::vector<int> lamps;    ///< lights: indices into /lighting/lamps switched; empty = the global level
  std::string path;          ///< JSON path, for messages
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
  std::vector<EventConfig> events;  ///< sorted by time
  sim::OcclusionMask occlusion;     ///< for the whole run (paper 002 table 1)
  sim::Lighting lighting;           ///< at t = 0
  std::vector<Eigen::Vector2d> sun_velocity;  ///< m/s per sun patch (sun moving slowly)
  Json localizer;            ///< {"type": ..., params}
  Json camera;               ///< camera configuration (profile defaults merged)
  Json vision;               ///< vision front-end configuration (calibration, colour table, scan lines)
  Json effective;            ///< every value read, defaults filled in: saved as config.json

  const RobotConfig* robot(int id) const;
  /// Lighting at time t: lamp events applied with their transitions, sun patches moved.
  sim::Lighting lighting_at(double t) const;
  /// Target of a teleport / kidnap event: its pose, or for "random" a pose inside the lines (0.5 m
  /// clear of them, any heading) drawn from `rng` (the run's stream "events", in event order).
  Pose2 event_target(const EventConfig& e, Rng& rng) const;
  std::vector<int> localized_robots() const;
};

/// Parses and validates; `name` defaults to the file's stem. Throws ConfigError.
Scenario parse_scenario(const Json& j, const std::string& name, const std::string& source = "");
/// Reads a scenario file (JSON syntax errors are ConfigErrors too, with line and column).
Scenario load_scenario(const std::string& path);
/// Builds everything the run would build (localizer, scripts) without running: full validation.
void validate_deep(const Scenario& s);

}  // namespace omniloc::harness
