#pragma once
// The run loop: steps the Box2D world at the physics rate, feeds sensors, and at the camera rate
// runs perception + localizer for every localized robot; scores against truth; writes the results
// directory atomically (everything goes to a temporary folder that is renamed at the end).
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "core/json_reader.hpp"
#include "harness/metrics.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

struct RunOptions {
  std::optional<std::uint64_t> seed;  ///< overrides the scenario's seed
  std::string out_dir;                ///< default: results/runs/<scenario>/<seed>
  std::string frames_dir;             ///< when set, every `frames_every`-th frame is saved as PNG
  int frames_every = 30;
  std::ostream* log = nullptr;        ///< progress and warnings (null: silent)
};

struct RobotResult {
  int robot = 0;
  ErrorSummary all;       ///< every frame with a valid estimate
  std::size_t frames = 0;
  std::size_t valid_frames = 0;
};

struct RunResult {
  std::string out_dir;
  std::uint64_t seed = 0;
  Json summary;
  std::vector<RobotResult> robots;
  std::string table;  ///< paper-format table, printed by the CLI
};

RunResult run_scenario(const Scenario& scenario, const RunOptions& options);

/// TUM trajectory line: "t x y z qx qy qz qw" (z = 0, rotation about z).
std::string tum_line(double t, const Pose2& p);

}  // namespace omniloc::harness
