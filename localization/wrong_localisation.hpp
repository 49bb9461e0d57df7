#pragma once
// Wrong-localisation detection shared by the hybrid (paper 002) and grid_global (paper 000)
// localizers: the distance of the line points from the nearest field line (at the tracked pose; the
// papers take the mean, we take an upper quantile, see line_deviation) AND |tracked heading - compass|
// above their thresholds for `consecutive` frames. The
// extension windows (either condition alone for longer) catch what the AND misses: a point-mirrored
// pose fits every line and only the compass disagrees; a kidnap that keeps the heading only shows
// in the deviation.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/pose2.hpp"
#include "localization/field_map.hpp"

namespace omniloc {

struct DetectionParams {
  double deviation_threshold = 0.25;  ///< m, the deviation_quantile of the points' distances to the nearest line
  /// Which quantile of the points' distances is "the deviation" (0.5 = median). 0.75 by measurement:
  /// the mean fired on correct poses (camera vibration puts far points decimetres off), the median
  /// missed wrong poses on which half of the points happen to lie near some line (random kidnaps).
  double deviation_quantile = 0.75;
  double heading_threshold = 0.35;    ///< rad, |tracked heading - compass|
  int consecutive = 5;                ///< papers 000 / 002: both conditions for this many frames
  int heading_only_frames = 15;       ///< extension (0 = off, the strict paper rule)
  int deviation_only_frames = 30;     ///< extension (0 = off)
  /// Reads the keys above from `r` (same level as the localizer's other keys).
  static DetectionParams from_json(JsonReader& r);
  static const ParamList<DetectionParams>& params();
};

/// The `quantile` (0..1) of the distances (metres) of the points (robot frame) from the nearest marking
/// at `pose` (world): the papers' "mean deviation", made robust to the far points' vibration error.
/// 0 for no points.
double line_deviation(const FieldMap& map, const std::vector<Eigen::Vector2d>& points, const Pose2& pose, double quantile);

class WrongLocalisationDetector {
 public:
  explicit WrongLocalisationDetector(const DetectionParams& p = {}) : p_(p) {}
  void reset() { both_ = heading_ = deviation_ = 0; }
  /// One tracked frame; true when the pose should be given up.
  bool update(double deviation, const Pose2& pose, std::optional<double> heading);
  const DetectionParams& params() const { return p_; }

 private:
  DetectionParams p_;
  int both_ = 0, heading_ = 0, deviation_ = 0;
};

}  // namespace omniloc
