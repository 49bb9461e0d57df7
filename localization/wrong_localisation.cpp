#include "localization/wrong_localisation.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"

namespace omniloc {

const ParamList<DetectionParams>& DetectionParams::params() {
  using P = DetectionParams;
  static const ParamList<P> list = {
      positive_param("deviation_threshold", &P::deviation_threshold, 10.0, "m", "wrong pose: the deviation_quantile of the points' distances to the nearest line above this"),
      number_param("deviation_quantile", &P::deviation_quantile, 0.0, 1.0, "", "which quantile of the distances is the deviation (0.5 = median; 0.75 by measurement)"),
      positive_param("heading_threshold", &P::heading_threshold, 3.2, "rad", "wrong pose: |tracked heading - compass| above this"),
      integer_param("consecutive", &P::consecutive, 1, 1000, "both conditions for this many frames (papers 000 / 002: 5)"),
      integer_param("heading_only_frames", &P::heading_only_frames, 0, 100000, "the heading condition alone for this many frames (extension; 0 = off)"),
      integer_param("deviation_only_frames", &P::deviation_only_frames, 0, 100000, "the deviation condition alone for this many frames (extension; 0 = off)"),
  };
  return list;
}

DetectionParams DetectionParams::from_json(JsonReader& r) {
  DetectionParams p;
  read_params(r, p, params());
  return p;
}

double line_deviation(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& pose, double quantile) {
  if (pts.empty()) return 0.0;
  // Not the papers' mean: far line points (6-7 m) are a few decimetres off through camera vibration
  // and a handful of them lift the mean of a correct pose to 0.2 m, next to the 0.25 m threshold.
  // The median of a correct pose stays at a few centimetres, but so does that of a wrong pose on
  // which half of the points happen to fall near some line; the upper quartile separates both.
  std::vector<double> d;
  d.reserve(pts.size());
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  for (const auto& o : pts) d.push_back(map.distance({pose.x + c * o.x() - s * o.y(), pose.y + s * o.x() + c * o.y()}));
  const auto k = std::min(d.size() - 1, static_cast<std::size_t>(std::clamp(quantile, 0.0, 1.0) * static_cast<double>(d.size())));
  const auto it = d.begin() + static_cast<std::ptrdiff_t>(k);
  std::nth_element(d.begin(), it, d.end());
  return *it;
}

bool WrongLocalisationDetector::update(double deviation, const Pose2& pose, std::optional<double> heading) {
  const bool bad_dev = deviation > p_.deviation_threshold;
  const bool bad_head = heading && std::fabs(angle_diff(pose.theta, *heading)) > p_.heading_threshold;
  both_ = bad_dev && bad_head ? both_ + 1 : 0;
  heading_ = bad_head ? heading_ + 1 : 0;
  deviation_ = bad_dev ? deviation_ + 1 : 0;
  const bool fire = both_ >= p_.consecutive || (p_.heading_only_frames > 0 && heading_ >= p_.heading_only_frames) ||
                    (p_.deviation_only_frames > 0 && deviation_ >= p_.deviation_only_frames);
  if (fire) reset();
  return fire;
}

}  // namespace omniloc
