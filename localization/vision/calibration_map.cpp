#include "localization/vision/calibration_map.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/json_reader.hpp"

namespace omniloc {

namespace {
// 4-point Lagrange interpolation at x over the nodes xs[i0..i0+3].
double lagrange4(const std::vector<double>& xs, const std::vector<double>& ys, std::size_t i0, double x) {
  double sum = 0;
  for (std::size_t i = i0; i < i0 + 4; ++i) {
    double l = 1;
    for (std::size_t j = i0; j < i0 + 4; ++j)
      if (j != i) l *= (x - xs[j]) / (xs[i] - xs[j]);
    sum += l * ys[i];
  }
  return sum;
}
Eigen::Vector2d image_dir(double bearing) { return {-std::sin(bearing), -std::cos(bearing)}; }
}  // namespace

double CalibrationMap::radial(std::size_t k, double r) const {
  const auto& rs = radii_[k];
  const auto& ds = distances_[k];
  const std::size_t n = rs.size();
  if (n < 4) return std::numeric_limits<double>::quiet_NaN();
  // The 4 nodes around r: two below and two above where possible.
  std::size_t hi = static_cast<std::size_t>(std::upper_bound(rs.begin(), rs.end(), r) - rs.begin());
  std::size_t i0 = hi >= 2 ? hi - 2 : 0;
  i0 = std::min(i0, n - 4);
  return lagrange4(rs, ds, i0, r);
}

std::optional<double> CalibrationMap::ground_distance(double r, double bearing) const {
  if (radii_.empty() || r < min_radius_ || r > max_radius_) return std::nullopt;
  const std::size_t n = radii_.size();
  const double step = kTwoPi / n;
  const double x = wrap_angle_positive(bearing) / step;
  const long k1 = static_cast<long>(std::floor(x));
  // Rotary: 4-point Lagrange over directions k1-1 .. k1+2 (periodic), evaluated at fraction x - k1.
  double sum = 0;
  const double f = x - k1;
  const double nodes[4] = {-1, 0, 1, 2};
  for (int i = 0; i < 4; ++i) {
    double l = 1;
    for (int j = 0; j < 4; ++j)
      if (j != i) l *= (f - nodes[j]) / (nodes[i] - nodes[j]);
    const std::size_t k = static_cast<std::size_t>(((k1 - 1 + i) % static_cast<long>(n) + static_cast<long>(n)) % static_cast<long>(n));
    const auto& rs = radii_[k];
    if (r < rs.front() || r > rs.back()) return std::nullopt;
    sum += l * radial(k, r);
  }
  return sum;
}

std::optional<Eigen::Vector2d> CalibrationMap::to_robot(double u, double v) const {
  const int iu = static_cast<int>(std::floor(u)), iv = static_cast<int>(std::floor(v));
  if (iu < 0 || iv < 0 || iu >= width_ || iv >= height_) return std::nullopt;
  const float* p = &lut_[(static_cast<std::size_t>(iv) * width_ + iu) * 2];
  if (std::isnan(p[0])) return std::nullopt;
  // The table holds the pixel centre; correct to (u, v) with the local radial scale is not needed
  // for line points (they are taken at pixel centres).
  return Eigen::Vector2d(p[0], p[1]);
}

std::optional<double> CalibrationMap::radius_for_distance(double distance, double bearing) const {
  // Bisection on the monotone radial map.
  double lo = min_radius_, hi = max_radius_;
  const auto dlo = ground_distance(lo, bearing), dhi = ground_distance(hi, bearing);
  if (!dlo || !dhi || distance < *dlo || distance > *dhi) return std::nullopt;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    const auto d = ground_distance(mid, bearing);
    if (!d) return std::nullopt;
    (*d < distance ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

void CalibrationMap::set_tables(int width, int height, Eigen::Vector2d centre, std::vector<std::vector<double>> radii_px,
                                std::vector<std::vector<double>> distances_m) {
  width_ = width;
  height_ = height;
  centre_ = centre;
  radii_ = std::move(radii_px);
  distances_ = std::move(distances_m);
  min_radius_ = 0;
  max_radius_ = std::numeric_limits<double>::infinity();
  for (const auto& rs : radii_) {
    min_radius_ = std::max(min_radius_, rs.front());
    max_radius_ = std::min(max_radius_, rs.back());
  }
  build_lut();
}

void CalibrationMap::build_lut() {
  lut_.assign(static_cast<std::size_t>(width_) * height_ * 2, std::numeric_limits<float>::quiet_NaN());
  for (int v = 0; v < height_; ++v)
    for (int u = 0; u < width_; ++u) {
      const Eigen::Vector2d d(u + 0.5 - centre_.x(), v + 0.5 - centre_.y());
      const double r = d.norm();
      if (r < min_radius_ || r > max_radius_) continue;
      const double b = std::atan2(-d.x(), -d.y());
      const auto g = ground_distance(r, b);
      if (!g) continue;
      float* p = &lut_[(static_cast<std::size_t>(v) * width_ + u) * 2];
      p[0] = static_cast<float>(*g * std::cos(b));
      p[1] = static_cast<float>(*g * std::sin(b));
    }
}

void CalibrationMap::save(const std::string& path) const {
  // Version 2 adds where the centre came from; the tables and "centre" mean what they did in 1.
  const nlohmann::json j{{"format", "omniloc-calibration-map"},
                         {"version", 2},
                         {"width", width_},
                         {"height", height_},
                         {"centre", {centre_.x(), centre_.y()}},
                         {"centre_source", rim_radius > 0 ? "rim" : "given"},
                         {"rim_radius_px", rim_radius},
                         {"tag", tag},
                         {"radii_px", radii_},
                         {"distances_m", distances_}};
  write_file_atomic(path, j.dump() + "\n");
}

CalibrationMap CalibrationMap::load(const std::string& path, const std::string& expected_tag, int width, int height) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, "no readable file", "a calibration map written by omniloc calibrate");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw ConfigError(path, "invalid JSON", std::string("a calibration map (") + e.what() + ")");
  }
  CalibrationMap m;
  try {
    if (j.at("format") != "omniloc-calibration-map" || (j.at("version") != 1 && j.at("version") != 2)) throw std::runtime_error("format");
    const auto radii = j.at("radii_px").get<std::vector<std::vector<double>>>();
    const auto dists = j.at("distances_m").get<std::vector<std::vector<double>>>();
    if (radii.size() < 4 || radii.size() != dists.size()) throw std::runtime_error("tables");
    for (std::size_t k = 0; k < radii.size(); ++k)
      if (radii[k].size() < 4 || radii[k].size() != dists[k].size() || !std::is_sorted(radii[k].begin(), radii[k].end()))
        throw std::runtime_error("direction " + std::to_string(k));
    m.tag = j.value("tag", "");
    m.rim_radius = j.at("version") == 2 ? j.at("rim_radius_px").get<double>() : 0.0;
    if (!std::isfinite(m.rim_radius) || m.rim_radius < 0) throw std::runtime_error("rim_radius_px");
    m.set_tables(j.at("width").get<int>(), j.at("height").get<int>(), {j.at("centre")[0].get<double>(), j.at("centre")[1].get<double>()}, radii, dists);
  } catch (const std::exception& e) {
    throw ConfigError(path, std::string("a malformed map (") + e.what() + ")", "format omniloc-calibration-map version 1 or 2 with >= 4 directions of >= 4 increasing radii");
  }
  if (!expected_tag.empty() && m.tag != expected_tag)
    throw ConfigError(path + "#tag", "\"" + m.tag + "\"", "a map calibrated for this camera (\"" + expected_tag + "\")");
  if ((width && m.width_ != width) || (height && m.height_ != height))
    throw ConfigError(path + "#width", std::to_string(m.width_) + "x" + std::to_string(m.height_),
                      "a map of the camera's image size " + std::to_string(width) + "x" + std::to_string(height));
  return m;
}

// ---- The mirror centre from the rim ----------------------------------------------------------
//
// Why the rim: it is the strongest and most reliable edge in a catadioptric image. Outside the
// mirror disc the sensor sees the black of the camera housing (the simulator writes 0, a real camera
// its dark level), inside it the mirror's image of the hall, which is lit in every direction (the
// floor up to the horizon, the far floor above the walls). Taking the pixel-wise maximum over the
// calibration views (the robot turns, the mirror does not) removes whatever dark things the scene
// put near the rim in any one view (the calibration patch's black stripes, a black robot), so the
// rim step is large everywhere (about 150 DN just inside the rim of a default-camera frame, against
// a few DN of noise), and it lies on a circle of ~310 px: hundreds of independent edge points whose
// pixel quantisation (the simulator's rim is a hard, non-anti-aliased mask) averages out in the fit.
// The robot body's disc is also drawn on the mirror axis, but its edge is ~8x shorter (37.7 px
// radius for the default mirror: far fewer points, each with the same pixel quantisation), its
// contrast depends on the carpet and the light on the robot, and on a real robot the body is seen
// through the mirror's inner part; the patch symmetry needs the patch's edges, which are
// themselves what the centre is for. The rim is used alone.
namespace {

// Bilinear sample of a single-channel float image at (x, y) in pixel coordinates with pixel centres
// at +0.5; nullopt when the 2x2 neighbourhood is not inside the image.
std::optional<double> sample(const cv::Mat& img, double x, double y) {
  x -= 0.5;
  y -= 0.5;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= img.cols || y0 + 1 >= img.rows) return std::nullopt;
  const double fx = x - x0, fy = y - y0;
  auto g = [&](int xx, int yy) { return static_cast<double>(img.at<float>(yy, xx)); };
  return (1 - fy) * ((1 - fx) * g(x0, y0) + fx * g(x0 + 1, y0)) + fy * ((1 - fx) * g(x0, y0 + 1) + fx * g(x0 + 1, y0 + 1));
}

// The rim along the ray from `c` in direction `dir`, searched from radius r0 outwards to the image
// border: the outermost strong outward drop after which the profile stays dark to the border, placed
// to sub-pixel at the crossing of the half level between the lit inside and the dark outside (for a
// hard or symmetrically blurred step that is the edge itself; the gradient's peak is a flat plateau
// for a hard mask seen through bilinear sampling).
std::optional<double> rim_on_ray(const cv::Mat& img, const Eigen::Vector2d& c, const Eigen::Vector2d& dir, double r0) {
  constexpr double kStep = 0.25;
  std::vector<double> g;
  for (double r = r0;; r += kStep) {
    const Eigen::Vector2d p = c + r * dir;
    const auto v = sample(img, p.x(), p.y());
    if (!v) break;
    g.push_back(*v);
  }
  const int n = static_cast<int>(g.size());
  constexpr int kHalf = 2;  // the drop is taken over 4 samples = 1 px
  if (n < 40) return std::nullopt;
  std::vector<double> drop(n, 0.0);
  double best = 0;
  for (int i = kHalf; i + kHalf < n; ++i) {
    drop[i] = g[i - kHalf] - g[i + kHalf];
    best = std::max(best, drop[i]);
  }
  if (best < 20.0) return std::nullopt;  // no lit-to-dark step at all on this ray
  int e = -1;
  for (int i = n - kHalf - 1; i >= kHalf; --i)
    if (drop[i] >= 0.5 * best) {
      e = i;
      break;
    }
  // The strongest drop within 2 px of the outermost strong one.
  for (int i = std::max(kHalf, e - 8); i <= std::min(n - kHalf - 1, e + 8); ++i)
    if (drop[i] > drop[e]) e = i;
  const int in0 = e - 20, in1 = e - 8, out0 = e + 8;
  if (in0 < 0 || out0 + 8 > n) return std::nullopt;  // too close to the start or to the image border (clipped rim)
  double inside = 0, outside = 0;
  for (int i = in0; i <= in1; ++i) inside += g[i] / (in1 - in0 + 1);
  for (int i = out0; i < n; ++i) outside = std::max(outside, g[i]);  // dark all the way to the border
  if (inside < 20.0 || outside > 0.25 * inside) return std::nullopt;
  const double half = 0.5 * (inside + outside);
  // The half-level crossing nearest the drop.
  double r_cross = -1, dist = 1e9;
  for (int i = in1; i < out0; ++i)
    if (g[i] >= half && g[i + 1] < half) {
      const double x = i + (g[i] - half) / (g[i] - g[i + 1]);
      if (std::fabs(x - e) < dist) {
        dist = std::fabs(x - e);
        r_cross = x;
      }
    }
  if (r_cross < 0) return std::nullopt;
  return r0 + r_cross * kStep;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

MirrorRim fit_circle(const std::vector<Eigen::Vector2d>& points, std::vector<bool>* inlier_out) {
  if (points.size() < 3) throw RuntimeFailure("circle fit: fewer than 3 points");
  std::vector<bool> inlier(points.size(), true);
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double R = 0;
  for (int round = 0; round < 20; ++round) {
    std::vector<Eigen::Vector2d> p;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (inlier[i]) p.push_back(points[i]);
    if (p.size() < 3) throw RuntimeFailure("circle fit: fewer than 3 inliers");
    // Kasa: x^2 + y^2 + D x + E y + F = 0, linear least squares, about the points' mean for
    // conditioning. Only the start of the geometric fit (Kasa is biased towards small circles on a
    // partial arc).
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& q : p) mean += q / static_cast<double>(p.size());
    Eigen::MatrixXd A(p.size(), 3);
    Eigen::VectorXd b(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Eigen::Vector2d q = p[i] - mean;
      A.row(static_cast<Eigen::Index>(i)) << q.x(), q.y(), 1.0;
      b(static_cast<Eigen::Index>(i)) = -q.squaredNorm();
    }
    const Eigen::Vector3d k = A.colPivHouseholderQr().solve(b);
    c = mean + Eigen::Vector2d(-0.5 * k(0), -0.5 * k(1));
    R = std::sqrt(std::max(0.0, 0.25 * (k(0) * k(0) + k(1) * k(1)) - k(2)));
    // Geometric: Gauss-Newton on the distances |p - c| - R.
    for (int it = 0; it < 20; ++it) {
      Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
      Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
      for (const auto& q : p) {
        const Eigen::Vector2d d = q - c;
        const double rho = std::max(1e-12, d.norm());
        const Eigen::Vector3d J(-d.x() / rho, -d.y() / rho, -1.0);
        JtJ += J * J.transpose();
        Jtr += J * (rho - R);
      }
      const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
      if (!step.allFinite()) break;
      c += step.head<2>();
      R += step(2);
      if (step.norm() < 1e-10) break;
    }
    // Outliers: beyond max(0.5 px, 3.5 robust sigmas) of the inliers' residuals.
    std::vector<double> abs_res;
    for (const auto& q : p) abs_res.push_back(std::fabs((q - c).norm() - R));
    const double limit = std::max(0.5, 3.5 * 1.4826 * median(abs_res));
    bool changed = false;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const bool in = std::fabs((points[i] - c).norm() - R) <= limit;
      changed |= in != inlier[i];
      inlier[i] = in;
    }
    if (!changed) break;
  }
  MirrorRim rim;
  rim.centre = c;
  rim.radius = R;
  double ss = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!inlier[i]) {
      ++rim.rejected;
      continue;
    }
    ++rim.edge_points;
    const double e = (points[i] - c).norm() - R;
    ss += e * e;
  }
  rim.rms_px = rim.edge_points ? std::sqrt(ss / rim.edge_points) : 0.0;
  if (inlier_out) *inlier_out = inlier;
  return rim;
}

MirrorRim estimate_mirror_rim(const std::vector<CalibrationView>& views, int directions) {
  if (views.empty()) throw RuntimeFailure("mirror rim: no images");
  const int W = views[0].image.width, H = views[0].image.height;
  cv::Mat brightest;  // pixel-wise maximum of the grey images
  for (const auto& view : views) {
    if (view.image.width != W || view.image.height != H) throw RuntimeFailure("mirror rim: images of different sizes");
    cv::Mat rgb(H, W, CV_8UC3, const_cast<std::uint8_t*>(view.image.rgb.data()));
    cv::Mat grey;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    if (brightest.empty())
      brightest = grey.clone();
    else
      cv::max(brightest, grey, brightest);
  }
  cv::Mat img;
  brightest.convertTo(img, CV_32F);
  // Pass 1 from the image centre (the mirror is near it: a mounting error of a few per cent of the
  // image at most); pass 2 from pass 1's centre, so that the rays cross the rim along its normal.
  Eigen::Vector2d c(0.5 * W, 0.5 * H);
  double r0 = 0.25 * std::min(W, H);
  MirrorRim rim;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector2d> pts;
    int missing = 0;
    for (int k = 0; k < directions; ++k) {
      const double a = kTwoPi * (k + 0.5) / directions;
      const Eigen::Vector2d dir(std::cos(a), std::sin(a));
      if (const auto r = rim_on_ray(img, c, dir, r0))
        pts.push_back(c + *r * dir);
      else
        ++missing;
    }
    if (pts.size() < 32)
      throw RuntimeFailure("mirror rim: found in only " + std::to_string(pts.size()) + " of " + std::to_string(directions) +
                           " directions (no dark outside the mirror in the images?)");
    rim = fit_circle(pts);
    rim.rejected += missing;
    c = rim.centre;
    r0 = 0.8 * rim.radius;
  }
  return rim;
}

namespace {

CalibrationResult calibrate_with_centre(const std::vector<CalibrationView>& views, const std::vector<double>& edge_distances,
                                        const Eigen::Vector2d& centre, double body_radius, double rmax) {
  CalibrationResult res;
  const int W = views[0].image.width, H = views[0].image.height;
  std::vector<std::pair<double, std::vector<double>>> found;  // bearing, radii
  for (const auto& view : views) {
    cv::Mat rgb(view.image.height, view.image.width, CV_8UC3, const_cast<std::uint8_t*>(view.image.rgb.data()));
    cv::Mat grey, blurred, edges;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    cv::GaussianBlur(grey, blurred, cv::Size(3, 3), 0.8);
    cv::Canny(blurred, edges, 30, 90);
    // Walk the ray in 0.25 px steps; an edge is a run of Canny pixels, located at the strongest
    // grey-profile gradient within it.
    const Eigen::Vector2d dir = image_dir(view.bearing);
    auto grey_at = [&](double r) {
      const Eigen::Vector2d p = centre + r * dir;
      const double x = p.x() - 0.5, y = p.y() - 0.5;
      const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= W || y0 + 1 >= H) return -1.0;
      const double fx = x - x0, fy = y - y0;
      auto g = [&](int xx, int yy) { return static_cast<double>(blurred.at<std::uint8_t>(yy, xx)); };
      return (1 - fy) * ((1 - fx) * g(x0, y0) + fx * g(x0 + 1, y0)) + fy * ((1 - fx) * g(x0, y0 + 1) + fx * g(x0 + 1, y0 + 1));
    };
    auto edge_at = [&](double r) {
      const Eigen::Vector2d p = centre + r * dir;
      const int x = static_cast<int>(p.x()), y = static_cast<int>(p.y());
      if (x < 1 || y < 1 || x + 1 >= W || y + 1 >= H) return false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (edges.at<std::uint8_t>(y + dy, x + dx)) return true;
      return false;
    };
    std::vector<double> radii;
    double r = body_radius + 2.0;
    while (r < rmax && radii.size() < edge_distances.size()) {
      if (!edge_at(r)) {
        r += 0.25;
        continue;
      }
      const double start = r;
      while (r < rmax && edge_at(r)) r += 0.25;
      double best = start, best_g = -1;
      for (double x = start - 1.0; x <= r + 1.0; x += 0.1) {
        const double a = grey_at(x - 0.5), b = grey_at(x + 0.5);
        if (a < 0 || b < 0) continue;
        if (std::fabs(b - a) > best_g) {
          best_g = std::fabs(b - a);
          best = x;
        }
      }
      if (best_g >= 8.0 && (radii.empty() || best > radii.back() + 1.0)) radii.push_back(best);
    }
    if (radii.size() == edge_distances.size()) {
      found.emplace_back(wrap_angle_positive(view.bearing), radii);
      ++res.directions_used;
    } else {
      ++res.directions_rejected;
    }
  }
  if (res.directions_used < 8)
    throw RuntimeFailure("calibration: only " + std::to_string(res.directions_used) + " of " + std::to_string(views.size()) +
                         " directions showed all " + std::to_string(edge_distances.size()) + " patch edges");
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  // Directions must be evenly spaced for the rotary interpolation: a rejected one is replaced by
  // interpolating its neighbours' radii.
  const std::size_t n = views.size();
  std::vector<std::vector<double>> radii(n), dists(n, edge_distances);
  for (std::size_t k = 0; k < n; ++k) {
    const double b = kTwoPi * k / n;
    const auto it = std::find_if(found.begin(), found.end(), [&](const auto& f) { return std::fabs(angle_diff(f.first, b)) < 1e-6; });
    if (it != found.end()) {
      radii[k] = it->second;
      continue;
    }
    // Nearest found neighbours on either side.
    const auto* lo = &found.back();
    const auto* hi = &found.front();
    for (const auto& f : found) {
      if (wrap_angle_positive(b - f.first) < wrap_angle_positive(b - lo->first)) lo = &f;
      if (wrap_angle_positive(f.first - b) < wrap_angle_positive(hi->first - b)) hi = &f;
    }
    const double a = wrap_angle_positive(b - lo->first), c = wrap_angle_positive(hi->first - b);
    radii[k].resize(edge_distances.size());
    for (std::size_t i = 0; i < edge_distances.size(); ++i) radii[k][i] = (c * lo->second[i] + a * hi->second[i]) / (a + c);
  }
  res.map.set_tables(W, H, centre, radii, dists);
  return res;
}

}  // namespace

CalibrationResult calibrate_from_images(const std::vector<CalibrationView>& views, const std::vector<double>& edge_distances,
                                        const Eigen::Vector2d& centre, double body_radius) {
  if (views.empty()) throw RuntimeFailure("calibration: no images");
  const int W = views[0].image.width, H = views[0].image.height;
  return calibrate_with_centre(views, edge_distances, centre, body_radius, 0.5 * std::min(W, H) - 1);
}

CalibrationResult calibrate_from_images(const std::vector<CalibrationView>& views, const std::vector<double>& edge_distances, double body_radius) {
  if (views.empty()) throw RuntimeFailure("calibration: no images");
  const MirrorRim rim = estimate_mirror_rim(views);
  // Edges are searched to 3 px inside the rim: the rim itself is the strongest Canny edge of all.
  CalibrationResult res = calibrate_with_centre(views, edge_distances, rim.centre, body_radius, rim.radius - 3.0);
  res.rim = rim;
  res.map.rim_radius = rim.radius;
  return res;
}

}  // namespace omniloc
