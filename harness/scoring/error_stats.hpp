#pragma once
// Error statistics of estimates against the truth: per-frame errors and their summary (mean, std and
// max per axis, position mean, RMSE and percentiles). The bottom of scoring: the robot's score
// (harness/scoring/metrics.hpp) and the recovery metrics (harness/scoring/recovery.hpp) both summarise
// errors with it.
#include <cstddef>
#include <vector>

#include "core/json_reader.hpp"

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
/// The summary's JSON. Over no frame (no estimate) every statistic is null, never 0: a localizer
/// that never answers must not score a perfect RMSE.
Json to_json(const ErrorSummary& s);

/// Percentile (0..100) of a sample by linear interpolation between order statistics.
double percentile(std::vector<double> v, double p);

}  // namespace omniloc::harness
