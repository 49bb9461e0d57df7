#pragma once
// The run loop: at every camera frame the Simulation advances to the frame time, each localized
// robot's camera frame goes through Perception and its localizer, and the frame is recorded; at the
// end metrics score the records against truth and run_writer writes the results directory atomically
// (everything goes to a temporary folder that is renamed at the end).
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>

#include "core/json_reader.hpp"
#include "harness/scoring/metrics.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

struct RunOptions {
  std::optional<std::uint64_t> seed;  ///< overrides the scenario's seed
  std::string out_dir;                ///< default: results/runs/<scenario>/<seed>
  std::string frames_dir;             ///< when set, every `frames_every`-th frame is saved as PNG
  int frames_every = 30;
  std::ostream* log = nullptr;        ///< progress and warnings (null: silent)
  /// The frames come from a recording: a localizer without vision gets what a live run without a
  /// camera would give it (no line points, no camera settings, no perception events).
  bool replay = false;
  /// Also write view.jsonl: per frame and robot, what the localizer was given (line points, blobs)
  /// and what it held (covariance, particles, points): docs/viewer.md section 4. The other files
  /// are the same with or without it.
  bool debug_view = false;
  std::size_t debug_particles = 200;  ///< at most this many particles a line
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

/// A live run: simulation and perception (harness/frame_source.hpp LiveSource) into the localizer.
RunResult run_scenario(const Scenario& scenario, const RunOptions& options);

class FrameSource;
/// The run loop over any frame source: `scenario` gives the localizer, the scoring events and the
/// effective configuration; `provenance` is added to summary.json's "omniloc" block.
RunResult run_frames(const Scenario& scenario, std::uint64_t seed, FrameSource& source, const RunOptions& options, const Json& provenance);

/// The frames of a run whose source is chosen once its localizers are started: an external client's
/// `ready` says whether it wants images. Called once with that answer and the provenance to complete.
using FramesFor = std::function<FrameSource&(bool wants_images, Json& provenance)>;
/// As run_frames; `hello` gives what olp/1's hello announces (each robot's camera, blob detection)
/// and must agree with the source `frames` returns.
RunResult run_frames_after_hello(const Scenario& scenario, std::uint64_t seed, const FrameSource& hello, const FramesFor& frames,
                                 const RunOptions& options, Json provenance);

}  // namespace omniloc::harness
