#pragma once
// Scoring: the only place where ground truth meets estimates. A robot's score over a run (error
// statistics, recall, recovery from kidnaps, the tracking phase) and the papers' table layout (mean,
// std and max of |x|, |y| errors in cm and |theta| error in rad) plus position mean, RMSE and
// percentiles.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "harness/events.hpp"
#include "harness/scoring/error_stats.hpp"
#include "harness/run_record.hpp"

namespace omniloc::harness {

/// One recall threshold: a frame counts as localized when its estimate lies within `position_m`
/// (metres) and `heading_rad` (radians) of the truth. `key` names it in summary.json ("25cm_10deg").
struct RecallThreshold {
  double position_m = 0.25, heading_rad = 0.0;
  std::string key;
  /// Whether an error (metres, metres, radians wrapped) lies within both limits.
  bool contains(const FrameError& e) const { return std::hypot(e.ex, e.ey) <= position_m && std::fabs(e.eth) <= heading_rad; }
};

/// How a run is scored beyond the error statistics (scenario key "scoring", docs/results.md).
struct Scoring {
  /// Default (position, heading) thresholds, fitted to a RoboCup MSL field and robot:
  /// 10 cm / 5 deg is tracking quality (matching's p95 on the tracking path is 6.4 cm; at 5 m a
  ///   5 deg heading error moves a pass 44 cm, two ball diameters);
  /// 25 cm / 10 deg is the robot's own size (an MSL robot's footprint is at most 52 x 52 cm);
  /// 50 cm / 20 deg is the line past which summary.json calls a frame wrong (wrong_frames:
  ///   0.5 m or 0.35 rad).
  /// The middle one also times global starts (first_within_s).
  std::vector<RecallThreshold> recall = default_recall();
  static std::vector<RecallThreshold> default_recall();
  static RecallThreshold threshold(double position_m, double heading_deg);
  /// Reads {"recall": [{"position_m", "heading_deg"}, ...]} (1 to 8 thresholds); `path` for errors.
  static Scoring from_json(const Json& j, const std::string& path, Json* effective = nullptr);
  const RecallThreshold& middle() const { return recall[recall.size() / 2]; }
};

/// The share of `frames` scored frames whose estimate lies within each threshold: {"10cm_5deg":
/// 0.93, ...}. `answered`: the errors of the frames with an estimate; every other frame counts as
/// outside every threshold. Null values when `frames` is 0.
Json recall_json(const std::vector<FrameError>& answered, std::size_t frames, const Scoring& scoring);

/// One row of a paper-format table.
struct TableRow {
  std::string label;
  ErrorSummary s;
  std::size_t frames_total = 0;    ///< frames scored, answered or not
  double recall = 0.0;             ///< share of frames_total within the middle threshold
  std::string recall_key;          ///< that threshold's name
};
/// The papers' layout: | case | mean x | mean y | mean th | std x | std y | std th | max x | max y | max th |
/// followed by frames, the share of frames answered, position RMSE / p95 and the recall at the
/// middle threshold. Plain text, fixed width; a row over no frame says "no estimate".
std::string paper_table(const std::vector<TableRow>& rows);

/// The score of one localized robot over a run.
struct RobotScore {
  ErrorSummary all;                            ///< every frame with a valid estimate
  std::optional<ErrorSummary> tracking_phase;  ///< with kidnaps or covers: the frames the papers' tables describe
  TableRow all_row, tracking_row;              ///< their rows of the terminal table (labels left empty)
  Json json;                                   ///< the robot's entry of summary.json
};

/// Scores a robot's frames: the error statistics, vision statistics (line points, coasting), the
/// failures stated rather than averaged away (relocalisations, wrong and point-mirrored frames),
/// recovery from each kidnap and, with kidnaps or covers, the tracking phase (split_tracking_phase).
/// `events`: the scenario's, in time order; `duration`: the run's, seconds.
RobotScore score_robot(const RobotRecord& robot, const std::vector<Event>& events, double duration, const Scoring& scoring = {});

/// Relative pose error (the TUM / evo RPE, no alignment: the field frame is known) over one frame
/// and over one second: for each pair of frames (i, j) with both estimates valid, E = (T_i^-1 T_j)^-1
/// (P_i^-1 P_j); translation and rotation RMS of E over the pairs. Pairs across a move without
/// odometry (`moves`: teleport and kidnap times) are left out. Null statistics over no pair.
Json rpe_json(const RobotRecord& robot, const std::vector<double>& moves);


}  // namespace omniloc::harness
