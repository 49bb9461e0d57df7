#pragma once
// The simulated side of a run: the Box2D world, every robot's motion script, the scripted events,
// the localized robots' odometry and heading sensors, and the camera's latency. One object advances
// all of it to a time, so the run loop, `omniloc render` and the experiments see the same world for
// the same scenario and seed (random event targets included).
//
// Units: seconds, metres, radians; poses in the world frame.
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "core/rng.hpp"
#include "harness/perception.hpp"
#include "harness/scenario.hpp"
#include "sim/motion.hpp"
#include "sim/sensors.hpp"
#include "sim/world.hpp"

namespace omniloc::harness {

/// events.jsonl, one JSON record a line, in the order things happened.
class EventLog {
 public:
  void add(const Json& record) { text_ += record.dump() + "\n"; }
  /// A record already serialised (one JSON object, no newline).
  void add_line(const std::string& line) { text_ += line + "\n"; }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

/// What a localized robot's own sensors report at a camera frame.
struct SensorReadings {
  Odometry odometry;              ///< motion since the previous reading
  std::optional<double> heading;  ///< compass / MTi, world frame (none without a heading sensor)
};

class Simulation {
 public:
  /// Builds the world, scripts and sensors of `s` for run seed `seed`. `log` (may be null) receives
  /// the events as they are applied.
  Simulation(const Scenario& s, std::uint64_t seed, EventLog* log = nullptr);
  ~Simulation();

  /// Steps physics until time t: before each step the events due are applied and every robot gets
  /// its script's command (paused robots stand still); after it the sensors accumulate.
  void advance_to(double t);
  double time() const;

  /// The world now, with the scenario's lighting at this time.
  sim::WorldState state() const;
  /// What robot's camera shows at this time: the newest state at least the camera latency old
  /// (lighting as now); `now` is state().
  sim::WorldState camera_view(const sim::WorldState& now) const;
  /// The scripted conditions of this frame for `robot` (covered lens, occlusion sectors in the robot
  /// frame of its true heading in `now`).
  FrameConditions conditions(int robot, const sim::WorldState& now) const;
  /// Odometry since the last reading and the heading sensor of a localized robot.
  SensorReadings read_sensors(int robot, const sim::WorldState& now);
  bool in_contact(int robot) const;

  /// The robot stands still from the next step on (its camera is adjusting, paper 002).
  void set_paused(int robot, bool paused);
  bool paused(int robot) const;

  // Used by the events (harness/events.cpp).
  void teleport(int robot, const Pose2& pose);
  void cover_camera(int robot, double until);
  void occlude_camera(int robot, double until, const sim::OcclusionMask& mask);
  /// Until `until`, the robot's odometry accumulates `scale` times its wheel motion.
  void slip_wheels(int robot, double until, double scale);
  /// A pose 0.5 m inside the lines, any heading, from the run's stream "events" (in event order).
  Pose2 random_pose_on_field();

 private:
  struct Sensors {
    std::unique_ptr<sim::OdometrySensor> odometry;
    std::unique_ptr<sim::HeadingSensor> heading;
    bool has_heading = true;
    double slip_until = -1.0;  ///< seconds
    double slip_scale = 1.0;
  };
  struct CameraState {
    double covered_until = -1.0;
    double occluded_until = -1.0;
    sim::OcclusionMask mask;
  };

  const Scenario& sc_;
  EventLog* log_;
  sim::World world_;
  std::map<int, std::unique_ptr<sim::MotionScript>> scripts_;
  std::map<int, Sensors> sensors_;  ///< localized robots only
  std::map<int, CameraState> cameras_;
  std::map<int, bool> paused_;
  std::size_t next_event_ = 0;
  Rng event_rng_;
  double latency_ = 0.0;                 ///< seconds
  std::deque<sim::WorldState> history_;  ///< for the latency, when > 0
};

}  // namespace omniloc::harness
