#pragma once
// What a run records per camera frame of each localized robot: the truth (for scoring only), the
// localizer's answer, the vision statistics and the wall-clock stage times. The scoring
// (harness/scoring/metrics) and the result files (harness/run_writer) are computed from these records alone.
#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "localization/localizer.hpp"

namespace omniloc::harness {

struct FrameRecord {
  double t = 0.0;         ///< seconds
  Pose2 truth, est;       ///< world frame
  bool valid = false;     ///< the localizer stood behind `est`
  bool camera_ok = false; ///< the image was usable
  bool contact = false;   ///< the robot touched another body in the physics step
  LocalizerMode mode = LocalizerMode::kNone;
  std::string mode_label;  ///< an external localizer's own mode word (written instead of mode when set)
  std::size_t points = 0; ///< line points found in the image
  double match_error = 0.0;
  std::map<std::string, double> extra;  ///< localizer extras and the camera settings (frames.csv columns)
  double render_ms = 0.0, vision_ms = 0.0, localize_ms = 0.0;  ///< wall time: timing.csv only
  std::optional<double> compute_ms;  ///< an external client's own time for the frame (ms): timing.csv only
  // What the accuracy bound (harness/scoring/bound.hpp) needs of the frame, as the localizer got it:
  // scoring only. Floats: a micrometre at 10 m, half the memory of a run's points.
  std::vector<std::array<float, 2>> line_points;  ///< robot frame, metres
  Pose2 odometry;                 ///< increment since the previous frame, robot frame of that frame
  std::optional<double> heading;  ///< compass / MTi reading, world frame (none without one)
};

struct RobotRecord {
  int id = 0;
  std::vector<FrameRecord> frames;
  bool has_truth = true;  ///< false for a log without ground truth: `truth` is meaningless, nothing is scored
};

}  // namespace omniloc::harness
