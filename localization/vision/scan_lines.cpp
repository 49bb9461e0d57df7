#include "localization/vision/scan_lines.hpp"

#include <cmath>

#include "core/angles.hpp"

namespace omniloc {

const ParamList<ScanLineParams>& ScanLineParams::params() {
  using P = ScanLineParams;
  static const ParamList<P> list = {
      integer_param("rays", &P::rays, 4, 720, "radial scan lines (paper 002: 72)"),
      positive_param("max_distance", &P::max_distance, 20.0, "m", "farther floor is not scanned (points too unreliable)"),
      positive_param("line_width", &P::line_width, 1.0, "m", "the field's painted line width"),
      number_param("width_factor", &P::width_factor, 1.0, 20.0, "", "a white run may be this many times the expected width (oblique crossings)"),
      number_param("width_slack_px", &P::width_slack_px, 0.0, 20.0, "px", "... plus this many pixels (blur)"),
      number_param("min_width_factor", &P::min_width_factor, 0.0, 1.0, "",
                   "a white run must be at least this many times the expected width, less width_slack_px (a ray crosses a line over at least its width)"),
      integer_param("max_gap", &P::max_gap, 0, 10, "unknown pixels allowed between green and white (anti-aliasing)"),
      number_param("dark_mean", &P::dark_mean, 0.0, 255.0, "grey level", "mean grey below this: the camera is covered, no observation"),
  };
  return list;
}

ScanLineParams ScanLineParams::from_json(JsonReader& r) {
  ScanLineParams p;
  read_params(r, p, params());
  return p;
}

namespace {
constexpr double kStep = 0.5;  ///< px between the radii a scan line samples (each pixel taken once)
}  // namespace

LineDetector::LineDetector(const ScanLineParams& p, const CalibrationMap& map, const ColourTable& table) : p_(p), map_(map), table_(table) {
  const Eigen::Vector2d c = map.centre();
  for (int k = 0; k < p.rays; ++k) {
    const double b = kTwoPi * k / p.rays;
    const Eigen::Vector2d dir(-std::sin(b), -std::cos(b));
    Ray ray{Eigen::Vector2d(std::cos(b), std::sin(b)), {}};
    int last_u = -1, last_v = -1;
    for (double r = map.min_radius() + 1.0; r <= map.max_radius(); r += kStep) {
      const auto d = map.ground_distance(r, b);
      if (!d) continue;
      if (*d > p.max_distance) break;
      const Eigen::Vector2d px = c + r * dir;
      const int u = static_cast<int>(px.x()), v = static_cast<int>(px.y());
      if (u == last_u && v == last_v) continue;
      if (u < 0 || v < 0 || u >= map.image_width() || v >= map.image_height()) break;
      last_u = u;
      last_v = v;
      const auto d1 = map.ground_distance(r + 0.5, b), d0 = map.ground_distance(r - 0.5, b);
      const double m_per_px = (d1 && d0) ? std::max(1e-4, *d1 - *d0) : 0.01;
      // Each sample's r is the first kStep inside its pixel: the ray entered the pixel kStep / 2
      // before it on average.
      const auto entry = map.ground_distance(r - 0.5 * kStep, b);
      if (!entry) continue;
      ray.samples.push_back({u, v, r, p.line_width / m_per_px, *entry});
    }
    rays_.push_back(std::move(ray));
  }
}

ScanResult LineDetector::detect(const Image& img) const {
  ScanResult res;
  double grey_sum = 0;
  std::size_t grey_n = 0;
  for (const auto& [ray_dir, ray] : rays_) {
    int green_end = -1000;  // index of the last green sample
    int white_start = -1;
    for (int i = 0; i < static_cast<int>(ray.size()); ++i) {
      const Sample& s = ray[i];
      const std::uint8_t* px = img.row(s.v) + 3 * s.u;
      grey_sum += px[0] + px[1] + px[2];
      grey_n += 3;
      const std::uint8_t c = table_.classify(px);
      if (c == kObstacleBlack) {
        ++res.rays_blocked;
        break;
      }
      if (c == kFieldGreen) {
        if (white_start >= 0) {
          // End of a white run followed by green (within the allowed gap): a candidate line point.
          int white_end = i - 1;
          while (white_end > white_start && table_.classify(img.row(ray[white_end].v) + 3 * ray[white_end].u) != kLineWhite) --white_end;
          if (i - white_end - 1 <= p_.max_gap) {
            // The run spans from where the ray enters its first white pixel to where it enters the
            // next one (ray[white_end + 1] exists: the green sample i lies beyond). (Taking the last
            // white pixel's entry as the far end put every line point half a pixel, about 1.2 cm at
            // 3 m, short of the line's centre until commit 6184583: tests/vision_test.cpp.)
            const Sample &first = ray[white_start], &beyond = ray[white_end + 1];
            const double len = beyond.r - first.r;
            const Sample& mid = ray[(white_start + white_end) / 2];
            if (len <= p_.width_factor * mid.expected_px + p_.width_slack_px && len >= p_.min_width_factor * mid.expected_px - p_.width_slack_px) {
              // The line's centre is the middle of its two edges on the floor, taken along the ray's
              // own bearing. The middle in image radius is not: within 1 m the mirror's law is
              // curved, and it put the point up to 1.3 cm short of the line at 0.45 m
              // (docs/modern_localizer.md "The bias's cause"); and the calibration table's value at
              // the pixel holding that middle moved it by up to half a pixel across and along the ray.
              res.points.push_back(0.5 * (first.entry_m + beyond.entry_m) * ray_dir);
              res.pixels.push_back(map_.centre() + (0.5 * (first.r + beyond.r) - 0.5 * kStep) * Eigen::Vector2d(-ray_dir.y(), -ray_dir.x()));
            }
          }
          white_start = -1;
        }
        green_end = i;
      } else if (c == kLineWhite) {
        if (white_start < 0 && i - green_end - 1 <= p_.max_gap) white_start = i;
      } else if (white_start < 0 && i - green_end > p_.max_gap + 1) {
        green_end = -1000;  // a long stretch of something else: no transition from green
      }
    }
  }
  res.mean_grey = grey_n ? grey_sum / grey_n : 0.0;
  return res;
}

Observations LineDetector::observe(const Image& img, double t) const {
  Observations o;
  o.t = t;
  const ScanResult r = detect(img);
  o.camera_ok = r.mean_grey >= p_.dark_mean;
  if (o.camera_ok) o.line_points = r.points;
  return o;
}

}  // namespace omniloc
