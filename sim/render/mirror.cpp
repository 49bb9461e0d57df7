#include "sim/render/mirror.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/angles.hpp"
#include "core/error.hpp"

namespace omniloc::sim {

namespace {

// NuBot-style composite mirror (paper 002, sec. 2; parameters ours, chosen for a 640 px image):
// an inner part near the robot where the image is most magnified (a hyperbolic profile's
// behaviour, modelled by an exponential radius-distance law), a horizontally isometric middle
// part where image radius is linear in floor distance (1 m to 8 m: 170 px over 7 m, so a 0.125 m
// line is 3 px wide at any distance there), and a vertically isometric outer part where radius is
// linear in elevation, up to 8 degrees above the horizon. The inner law joins the middle one with
// equal slope so that the model-free calibration can interpolate across the joint.
struct Composite {
  double s, h;
  double rb, r1, r2, R;
  double db = 0.30, d1 = 1.0, d2 = 8.0, emax = deg2rad(8.0);
  double k, c, lambda;
  Composite(double rim, double height) : s(rim / 316.0), h(height) {
    rb = 38 * s;
    r1 = 110 * s;
    r2 = 280 * s;
    R = rim;
    k = (r2 - r1) / (d2 - d1);  // px per metre in the isometric part
    const double L = r1 - rb, target = (1.0 / k) / (d1 - db);
    double lo = 1e-6, hi = 1.0;  // solve lambda e^(lambda L) / (e^(lambda L) - 1) = target
    for (int i = 0; i < 200; ++i) {
      const double m = 0.5 * (lo + hi);
      const double f = m * std::exp(m * L) / std::expm1(m * L);
      (f < target ? lo : hi) = m;
    }
    lambda = 0.5 * (lo + hi);
    c = (d1 - db) / std::expm1(lambda * L);
  }
  double distance(double r) const {  // floor distance for r in [rb, r2]
    if (r <= r1) return db + c * std::expm1(lambda * (r - rb));
    return d1 + (r - r1) / k;
  }
  double elevation(double r) const {
    if (r <= r2) return -std::atan2(h, distance(r));
    const double e2 = -std::atan2(h, d2);
    return e2 + (r - r2) / (R - r2) * (emax - e2);
  }
};

}  // namespace

MirrorProfile MirrorProfile::preset(const std::string& name, double rim_px, double mount_height) {
  if (!(rim_px > 8.0)) throw ConfigError("/camera/width", std::to_string(rim_px), "an image large enough for a mirror (>= 16 px)");
  MirrorProfile m;
  m.name_ = name;
  m.h_ = mount_height;
  m.rim_px_ = rim_px;
  std::function<double(double)> elev_of_r;
  if (name == "nubot_composite") {
    const Composite comp(rim_px, mount_height);
    m.body_px_ = comp.rb;
    elev_of_r = [comp](double r) { return comp.elevation(r); };
  } else if (name == "hyperbolic") {
    // Single-viewpoint hyperbolic mirror in the unified projection model (Geyer / Barreto):
    // r = g sin(b) / (xi + cos(b)), b the ray angle from the downward axis; xi = 0.8.
    const double xi = 0.8, bmax = kPi / 2 + deg2rad(8.0);
    const double g = rim_px * (xi + std::cos(bmax)) / std::sin(bmax);
    const double bb = std::atan2(0.30, mount_height);  // the body covers the floor within 0.3 m
    m.body_px_ = g * std::sin(bb) / (xi + std::cos(bb));
    // Invert r(b) by bisection (monotone on [0, bmax]).
    elev_of_r = [g, xi, bmax](double r) {
      double lo = 0, hi = bmax;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (g * std::sin(mid) / (xi + std::cos(mid)) < r ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi) - kPi / 2;
    };
  } else if (name == "nubot_tan") {
    // A measured mirror: NuBot's published calibration of one of its robots (nubot-nudt/nubot_ws,
    // src/nubot/omni_vision/calib_results/2/mirror_calib.xml and ROI.xml): floor distance
    // d(r) = a tan(b r), a = 1.6768 m, b = 0.0067311 rad/px on a 485 px image whose mirror ends at
    // max_radius = pi / (2b) = 233.4 px, the horizon; the robot's body hides the image within
    // small_radius = 38 px, i.e. the floor within a tan(38 b) = 0.44 m. Scaled to this image's rim
    // (b = pi / (2 rim)), so the horizon again falls on the rim; a and the body's floor radius are kept.
    const double a = 1.6768, b = kPi / (2.0 * rim_px), body_floor = 1.6768 * std::tan(38.0 * 0.0067311);
    m.body_px_ = std::atan(body_floor / a) / b;
    elev_of_r = [a, b, mount_height](double r) { return r >= kPi / (2.0 * b) ? 0.0 : -std::atan2(mount_height, a * std::tan(b * r)); };
  } else {
    std::string known;
    for (const auto& p : presets()) known += (known.empty() ? "\"" : ", \"") + p + "\"";
    throw ConfigError("/camera/mirror", "\"" + name + "\"", "a mirror preset: " + known);
  }
  // Dense table from the body edge to the rim (0.05 px steps) for fast lookups both ways.
  const int n = static_cast<int>((rim_px - m.body_px_) / 0.05) + 2;
  for (int i = 0; i < n; ++i) {
    const double r = std::min(rim_px, m.body_px_ + i * 0.05);
    m.r_.push_back(r);
    m.e_.push_back(elev_of_r(r));
  }
  return m;
}

double MirrorProfile::radius(double e) const {
  // Beyond the table: continue linearly with the end slopes (those rays fall inside the body
  // disc or outside the rim, where nothing of them is visible).
  if (e <= e_.front()) {
    const double slope = (r_[1] - r_[0]) / (e_[1] - e_[0]);
    return std::max(0.0, r_.front() + (e - e_.front()) * slope);
  }
  if (e >= e_.back()) {
    const std::size_t n = e_.size();
    const double slope = (r_[n - 1] - r_[n - 2]) / (e_[n - 1] - e_[n - 2]);
    return r_.back() + (e - e_.back()) * slope;
  }
  const auto it = std::upper_bound(e_.begin(), e_.end(), e);
  const std::size_t i = static_cast<std::size_t>(it - e_.begin());
  const double f = (e - e_[i - 1]) / (e_[i] - e_[i - 1]);
  return r_[i - 1] + f * (r_[i] - r_[i - 1]);
}

double MirrorProfile::elevation(double r) const {
  const double x = (r - r_.front()) / 0.05;
  if (x <= 0) return e_.front();
  const std::size_t i = static_cast<std::size_t>(x);
  if (i + 1 >= e_.size()) return e_.back();
  const double f = (r - r_[i]) / (r_[i + 1] - r_[i]);
  return e_[i] + f * (e_[i + 1] - e_[i]);
}

double MirrorProfile::elevation_of_floor(double distance) const { return -std::atan2(h_, distance); }

}  // namespace omniloc::sim
