#pragma once
// Scripted scenario events. Each kind is one struct holding its parameters and, in events.cpp, its
// parse (from the scenario file); what it does to the running Simulation and what events.jsonl logs
// of it is its apply function in simulation.cpp. An event is a time, a robot and one of those kinds
// in a std::variant. Adding a kind: a struct here, its parse in events.cpp, its apply in
// simulation.cpp, a test and a row in docs/scenario.md (docs/extending.md).
//
// Units: seconds, metres, radians; poses in the world frame.
#include <string>
#include <variant>
#include <vector>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "sim/world_state.hpp"
#include "sim/occlusion.hpp"

namespace omniloc::harness {

/// Moves the robot instantly to `pose` (no odometry of the move).
struct Teleport {
  static constexpr const char* kName = "teleport";
  Pose2 pose;
  bool random_pose = false;  ///< "pose": "random": drawn on the field from the run's stream "events"
};

/// Covers the camera, teleports, uncovers after `duration`; the localizer is not told.
struct Kidnap {
  static constexpr const char* kName = "kidnap";
  Pose2 pose;
  bool random_pose = false;
  double duration = 2.0;  ///< seconds the camera stays covered
};

/// The camera sees black for `duration` seconds.
struct Cover {
  static constexpr const char* kName = "cover";
  double duration = 1.0;
};

/// Black sectors painted into the panorama for `duration` seconds.
struct Occlude {
  static constexpr const char* kName = "occlude";
  double duration = 1.0;
  sim::OcclusionMask mask;
};

/// The lamps' global level (or, with `lamps`, those lamps' state: 0 off, 1 on) goes linearly to
/// `level` over `transition` seconds.
struct Lights {
  static constexpr const char* kName = "lights";
  double level = 1.0;
  double transition = 0.5;
  std::vector<int> lamps;  ///< indices into /lighting/lamps; empty = the global level
  /// Moves `l` towards this event's target as it stands at time t (the event started at t_event).
  void shade(sim::Lighting& l, double t_event, double t) const;
};

/// The wheels slip for `duration` seconds: odometry reports `scale` times the wheel motion (above 1:
/// wheels spinning on the carpet while the robot is held; 0: a lifted robot's encoders see nothing).
struct Slip {
  static constexpr const char* kName = "slip";
  double duration = 1.0;
  double scale = 1.5;
};

using EventKind = std::variant<Teleport, Kidnap, Cover, Occlude, Lights, Slip>;

struct Event {
  double t = 0.0;    ///< seconds
  int robot = 0;     ///< the robot it acts on (lights: ignored by the world, logged)
  std::string path;  ///< JSON path, for messages
  EventKind kind;

  template <class K>
  const K* as() const { return std::get_if<K>(&kind); }
  /// The kind's name as in scenario files and events.jsonl ("teleport", "kidnap", ...).
  std::string type() const;
  /// Kidnaps and covers interrupt tracking: the papers' tables describe the frames between them.
  bool disrupts_tracking() const { return as<Kidnap>() || as<Cover>(); }
  /// Seconds the event lasts (cover, kidnap, occlude, slip), else 0.
  double duration() const;
};

/// What parsing an event needs to know about the scenario read so far.
struct EventContext {
  const Field* field = nullptr;
  double run_duration = 0.0;                  ///< events must start within the run
  int default_robot = 0;                      ///< the first localized robot
  std::vector<std::pair<int, double>> robots; ///< (id, radius) of every robot
};

/// Parses one element of /events at `path`. Lamp indices are checked later against /lighting.
Event parse_event(const Json& j, const std::string& path, const EventContext& ctx);

/// The names of every event kind, in the variant's order (for messages and docs).
std::vector<std::string> event_type_names();


}  // namespace omniloc::harness
