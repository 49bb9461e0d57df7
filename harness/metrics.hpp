#pragma once
// Scoring: the only place where ground truth meets estimates. Errors per frame, and the papers'
// table layout (mean, std and max of |x|, |y| errors in cm and |theta| error in rad) plus position
// mean, RMSE and percentiles.
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "harness/events.hpp"
#include "harness/run_record.hpp"

namespace omniloc::harness {

struct FrameError {
  double t = 0.0;
  double ex = 0.0, ey = 0.0;  ///< estimate - truth, world frame, metres
  double eth = 0.0;           ///< wrapped, radians
};

struct AxisStats {
  double mean = 0.0, std = 0.0, max = 0.0;  ///< of absolute errors
};

struct ErrorSummary {
  std::size_t frames = 0;        ///< frames scored
  AxisStats x_cm, y_cm;          ///< |x|, |y| errors, centimetres (papers' unit)
  AxisStats theta_rad;           ///< |theta| error, radians
  double pos_mean_m = 0.0;       ///< mean(hypot(ex, ey)), metres: the typical error (RMSE weighs large ones more)
  double pos_rmse_m = 0.0;       ///< sqrt(mean(ex^2 + ey^2)), metres
  double pos_p50_m = 0.0, pos_p90_m = 0.0, pos_p95_m = 0.0, pos_max_m = 0.0;
  double theta_rmse_rad = 0.0;
};

ErrorSummary summarize(const std::vector<FrameError>& errors);
Json to_json(const ErrorSummary& s);

/// One row of a paper-format table.
struct TableRow {
  std::string label;
  ErrorSummary s;
};
/// The papers' layout: | case | mean x | mean y | mean th | std x | std y | std th | max x | max y | max th |
/// followed by frames and position RMSE / p95. Plain text, fixed width.
std::string paper_table(const std::vector<TableRow>& rows);

/// The score of one localized robot over a run.
struct RobotScore {
  ErrorSummary all;                            ///< every frame with a valid estimate
  std::optional<ErrorSummary> tracking_phase;  ///< with kidnaps or covers: the frames the papers' tables describe
  Json json;                                   ///< the robot's entry of summary.json
};

/// Scores a robot's frames: the error statistics, vision statistics (line points, coasting), the
/// failures stated rather than averaged away (relocalisations, wrong and point-mirrored frames),
/// recovery from each kidnap and, with kidnaps or covers, the tracking phase (split_tracking_phase).
/// `events`: the scenario's, in time order; `duration`: the run's, seconds.
RobotScore score_robot(const RobotRecord& robot, const std::vector<Event>& events, double duration);

/// Percentile (0..100) of a sample by linear interpolation between order statistics.
double percentile(std::vector<double> v, double p);

}  // namespace omniloc::harness
