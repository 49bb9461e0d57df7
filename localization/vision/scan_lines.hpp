#pragma once
// Line points by radial scan lines (paper 002): rays from the image centre, outside the robot's own
// body; a line point is a green-white-green transition whose white run has a plausible width for its
// radius (the width a 0.125 m line has there, through the calibration map); its centre goes through
// the calibration map to the robot frame. A ray stops at the first obstacle (black) pixel, so robots
// and occluded (blackened) sectors give no points.
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/messages.hpp"
#include "localization/localizer.hpp"
#include "localization/vision/calibration_map.hpp"
#include "localization/vision/colour_table.hpp"

namespace omniloc {

struct ScanLineParams {
  int rays = 72;                 ///< paper 002: 72 radial scan lines
  double max_distance = 7.5;     ///< metres: farther floor is not scanned (points too unreliable)
  double line_width = 0.125;     ///< metres, the field's painted width
  double width_factor = 3.0;     ///< a white run may be this many times the expected width (oblique crossings) ...
  double width_slack_px = 2.0;   ///< ... plus this many pixels (blur)
  /// A white run must be at least this many times the expected width, less width_slack_px: a ray
  /// crosses a painted line over at least its width (the perpendicular crossing is the shortest), so a
  /// shorter run is not a line (docs/lighting.md "Strong sun without auto-adjustment": the flicker of a
  /// colour near the table's white/green boundary).
  double min_width_factor = 1.0;
  int max_gap = 2;               ///< unknown pixels allowed between green and white (anti-aliasing)
  double dark_mean = 15.0;       ///< mean grey below this: the camera is covered, no observation
  static ScanLineParams from_json(JsonReader& r);
  /// The JSON keys (scenario /vision/scan_lines), ranges and meanings (core/params.hpp).
  static const ParamList<ScanLineParams>& params();
};

struct ScanResult {
  std::vector<Eigen::Vector2d> points;  ///< robot frame, metres
  std::vector<Eigen::Vector2d> pixels;  ///< image positions of the same points
  int rays_blocked = 0;                 ///< rays stopped by an obstacle
  double mean_grey = 0.0;               ///< over the scanned pixels
};

class LineDetector {
 public:
  LineDetector(const ScanLineParams& p, const CalibrationMap& map, const ColourTable& table);
  ScanResult detect(const Image& img) const;
  /// detect() as the localizer's Observations (camera_ok = false when the image is dark).
  Observations observe(const Image& img, double t) const;
  const ScanLineParams& params() const { return p_; }

 private:
  struct Sample {
    int u, v;
    double r;
    double expected_px;  // width of a painted line at this radius
    double entry_m;      // floor distance (metres) where the ray enters this pixel, on average
  };
  struct Ray {
    Eigen::Vector2d dir;  ///< robot frame unit vector of the ray's bearing (the map's bearing convention)
    std::vector<Sample> samples;
  };
  ScanLineParams p_;
  const CalibrationMap& map_;
  const ColourTable& table_;
  std::vector<Ray> rays_;
};

}  // namespace omniloc
