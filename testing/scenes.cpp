#include "testing/scenes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "core/angles.hpp"
#include "localization/field_map.hpp"

namespace omniloc::scenes {

sim::CameraConfig quiet_camera() {
  sim::CameraConfig c;
  c.vibration_std = 0;
  c.read_noise = 0;
  c.shot_noise = 0;
  return c;
}

sim::WorldState one_robot(const Pose2& pose) {
  sim::WorldState w;
  sim::RobotState r;
  r.id = 0;
  r.pose = pose;
  w.robots.push_back(r);
  w.has_ball = false;
  return w;
}

std::vector<Eigen::Vector2d> line_points(const Field& f, const Pose2& pose, int n, Rng& rng, const LinePointOptions& o) {
  constexpr double kOnMarking = 0.004;  // metres from a marking's centre line
  std::vector<Eigen::Vector2d> pts;
  for (long draws = 0; static_cast<int>(pts.size()) < n && draws < o.max_draws; ++draws) {
    const Eigen::Vector2d w(pose.x + rng.uniform(-o.range, o.range), pose.y + rng.uniform(-o.range, o.range));
    if (o.area == LinePointOptions::Area::kDisc && (w - pose.translation()).norm() > o.range) continue;
    if (o.prefilter && o.prefilter->distance(w) > kOnMarking + 0.6 * o.prefilter->cell()) continue;
    if (f.distance_to_marking(w) > kOnMarking) continue;
    Eigen::Vector2d p = pose.inverse_transform(w);
    if (o.noise > 0) {
      // y before x: the order GCC evaluated the earlier Vector2d(normal(), normal()) in, kept so the
      // scenes stay the same numbers; written out, it no longer depends on the compiler.
      const double ny = rng.normal(0, o.noise);
      const double nx = rng.normal(0, o.noise);
      p += Eigen::Vector2d(nx, ny);
    }
    pts.push_back(p);
  }
  return pts;
}

void circumcircle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, Eigen::Vector2d& centre, double& r) {
  const double d = 2.0 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm(), c2 = c.squaredNorm();
  centre = {(a2 * (b.y() - c.y()) + b2 * (c.y() - a.y()) + c2 * (a.y() - b.y())) / d,
            (a2 * (c.x() - b.x()) + b2 * (a.x() - c.x()) + c2 * (b.x() - a.x())) / d};
  r = (a - centre).norm();
}

double distance_to_circle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& p) {
  Eigen::Vector2d centre;
  double r = 0;
  circumcircle(a, b, c, centre, r);
  return std::fabs((p - centre).norm() - r);
}

double distance_to_line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d u = (b - a).normalized();
  const Eigen::Vector2d v = p - a;
  return std::fabs(u.x() * v.y() - u.y() * v.x());
}

namespace {

// One configuration of landmark_configs.
std::vector<landmarks::BearingObs> landmark_config(Rng& rng, int n, double sigma) {
  for (;;) {
    std::vector<Eigen::Vector2d> L;
    while (static_cast<int>(L.size()) < n) {
      const Eigen::Vector2d c(rng.uniform(-9, 9), rng.uniform(-6, 6));
      bool ok = true;
      for (const auto& l : L) ok &= (l - c).norm() > 2.0;
      if (ok) L.push_back(c);
    }
    bool good = true;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d u = L[(i + 1) % 3] - L[i], v = L[(i + 2) % 3] - L[i];
      good &= std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0)) > deg2rad(15);
    }
    const Pose2 pose(rng.uniform(-10, 10), rng.uniform(-7, 7), rng.uniform(-kPi, kPi));
    const Eigen::Vector2d p = pose.translation();
    good = good && distance_to_circle(L[0], L[1], L[2], p) > 0.5 && distance_to_line(L[0], L[1], p) > 0.5 && distance_to_line(L[1], L[2], p) > 0.5;
    for (const auto& l : L) good &= (l - p).norm() > 0.5;
    if (!good) continue;
    std::vector<landmarks::BearingObs> obs;
    for (const auto& l : L) obs.push_back({l, wrap_angle(std::atan2(l.y() - pose.y, l.x() - pose.x) - pose.theta + rng.normal(0.0, sigma))});
    return obs;
  }
}

}  // namespace

const std::vector<std::vector<landmarks::BearingObs>>& landmark_configs(int n, double sigma) {
  static std::map<std::pair<int, double>, std::vector<std::vector<landmarks::BearingObs>>> made;
  auto& c = made[{n, sigma}];
  if (c.empty()) {
    Rng rng(2024 + n);
    for (std::size_t i = 0; i < kLandmarkConfigs; ++i) c.push_back(landmark_config(rng, n, sigma));
  }
  return c;
}

double mean_abs_diff(const Image& a, const Image& b, const Eigen::Vector2d& c, double r_min, double r_max) {
  double sum = 0;
  long n = 0;
  for (int v = 0; v < a.height; ++v)
    for (int u = 0; u < a.width; ++u) {
      const double r = (Eigen::Vector2d(u + 0.5, v + 0.5) - c).norm();
      if (r < r_min || r > r_max) continue;
      for (int ch = 0; ch < 3; ++ch) sum += std::abs(static_cast<int>(a.row(v)[3 * u + ch]) - static_cast<int>(b.row(v)[3 * u + ch]));
      n += 3;
    }
  return sum / static_cast<double>(n);
}

Image mean_image(int n, const std::function<Image(int k)>& render) {
  Image out = render(0);
  std::vector<double> acc(out.rgb.begin(), out.rgb.end());
  for (int k = 1; k < n; ++k) {
    const Image s = render(k);
    for (std::size_t i = 0; i < acc.size(); ++i) acc[i] += s.rgb[i];
  }
  for (std::size_t i = 0; i < acc.size(); ++i) out.rgb[i] = static_cast<std::uint8_t>(std::lround(acc[i] / n));
  return out;
}

}  // namespace omniloc::scenes
