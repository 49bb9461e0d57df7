#include "localization/vision/blobs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"

namespace omniloc {

namespace {

const std::vector<std::string> kBlobColourNames = {"yellow", "blue", "red"};

std::vector<ColourClass> to_classes(const std::vector<std::string>& names) {
  std::vector<ColourClass> out;
  for (const auto& n : names) {
    const ColourClass c = landmark_colour_class(n);
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  }
  return out;
}

// Per-region accumulators.
struct Region {
  double ref = 0.0;                 // reference bearing (centroid), radians
  double dmin = 0.0, dmax = 0.0;    // extent relative to ref, radians
  float rmin = std::numeric_limits<float>::max(), rmax = 0.0f;
  int imin = -1;                    // pixel index of the nearest pixel
};

}  // namespace

BlobParams BlobParams::from_json(JsonReader& r) {
  BlobParams p;
  p.colours = to_classes(r.strings("colours", kBlobColourNames, kBlobColourNames));
  if (r.has("edge_colours")) p.edge_colours = to_classes(r.strings("edge_colours", std::nullopt, kBlobColourNames));
  read_params(r, p, params());
  return p;
}

const ParamList<BlobParams>& BlobParams::params() {
  using P = BlobParams;
  static const ParamList<P> list = {
      integer_param("min_area_px", &P::min_area_px, 1, 1000000, "smaller regions (pixels) are ignored"),
      number_param("outer_radius_px", &P::outer_radius_px, 0.0, 100000.0, "px", "pixels searched out to this radius; 0 = the image's inscribed circle"),
      number_param("dark_mean", &P::dark_mean, 0.0, 255.0, "grey level", "mean grey of the annulus below this: camera covered, no blobs"),
      number_param("edge_extend_px", &P::edge_extend_px, 0.0, 10.0, "px", "widening of a region's angular extent on each side (0 by measurement)"),
      integer_param("edge_band_px", &P::edge_band_px, 1, 50, "pixels beyond an edge checked for an occluder"),
      number_param("occluded_fraction", &P::occluded_fraction, 0.0, 1.0, "", "fraction of those pixels that must be black (or off-image) for an occluded edge"),
      number_param("edge_contact_deg", &P::edge_contact_deg, 0.0, 45.0, "deg", "an edge's distance: nearest region pixel within this angle of it"),
  };
  return list;
}

BlobDetector::BlobDetector(const BlobParams& p, const CalibrationMap& map, const ColourTable& table)
    : p_(p), map_(map), table_(table), w_(map.image_width()), h_(map.image_height()) {
  const std::size_t n = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
  bearing_.resize(n);
  radius_.resize(n);
  inside_.resize(n);
  const Eigen::Vector2d c = map.centre();
  const double outer = p.outer_radius_px > 0 ? p.outer_radius_px : 0.5 * std::min(w_, h_);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
      const double du = u + 0.5 - c.x(), dv = v + 0.5 - c.y();
      const double r = std::hypot(du, dv);
      // Image direction of bearing b is (-sin b, -cos b): forward up, left to the left.
      bearing_[i] = static_cast<float>(std::atan2(-du, -dv));
      radius_[i] = static_cast<float>(r);
      inside_[i] = r >= map.min_radius() && r <= outer;
    }
}

double BlobDetector::mean_grey(const Image& img) const {
  if (img.width != w_ || img.height != h_) return 0.0;
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < inside_.size(); i += 4) {
    if (!inside_[i]) continue;
    const std::uint8_t* px = img.rgb.data() + 3 * i;
    sum += px[0] + px[1] + px[2];
    ++count;
  }
  return count ? sum / (3.0 * count) : 0.0;
}

std::vector<Blob> BlobDetector::detect(const Image& img) const {
  std::vector<Blob> out;
  if (img.width != w_ || img.height != h_ || img.rgb.size() < 3 * inside_.size()) return out;
  if (mean_grey(img) < p_.dark_mean) return out;

  // Classify the annulus once (everything outside it stays kUnknown), noting each wanted colour's
  // bounding box so connected components run on that box only (cubes are small).
  cv::Mat cls(h_, w_, CV_8U, cv::Scalar(0));
  std::array<bool, 256> wanted{};
  for (const ColourClass c : p_.colours) wanted[c] = true;
  std::array<int, 256> bx0, by0, bx1, by1;
  bx0.fill(w_);
  by0.fill(h_);
  bx1.fill(-1);
  by1.fill(-1);
  {
    std::uint8_t* dst = cls.ptr<std::uint8_t>(0);
    const std::uint8_t* src = img.rgb.data();
    for (int v = 0; v < h_; ++v) {
      const std::size_t row = static_cast<std::size_t>(v) * w_;
      for (int u = 0; u < w_; ++u) {
        const std::size_t i = row + u;
        if (!inside_[i]) continue;
        const std::uint8_t c = table_.classify(src + 3 * i);
        dst[i] = c;
        if (wanted[c]) {
          bx0[c] = std::min(bx0[c], u);
          bx1[c] = std::max(bx1[c], u);
          by0[c] = std::min(by0[c], v);
          by1[c] = std::max(by1[c], v);
        }
      }
    }
  }
  const Eigen::Vector2d c = map_.centre();
  auto class_at = [&](double r, double b) -> int {
    const int u = static_cast<int>(std::floor(c.x() - r * std::sin(b)));
    const int v = static_cast<int>(std::floor(c.y() - r * std::cos(b)));
    if (u < 0 || v < 0 || u >= w_ || v >= h_) return -1;
    return cls.at<std::uint8_t>(v, u);
  };
  // Whether the neighbourhood beyond an edge (direction s = +1 anticlockwise, -1 clockwise) is
  // mostly an occluder: black pixels or no image.
  auto occluded = [&](double edge, int s, const Region& g) {
    int n = 0, black = 0;
    for (double r = std::max<double>(g.rmin, map_.min_radius()); r <= g.rmax; r += 1.0)
      for (int k = 1; k <= p_.edge_band_px; ++k) {
        const int cl = class_at(r, edge + s * k / r);
        ++n;
        black += cl == -1 || cl == kObstacleBlack;
      }
    return n > 0 && black >= p_.occluded_fraction * n;
  };
  auto contact = [&](Blob& b, float rmin, int imin) {
    // The nearest pixel's inner border; hidden behind the body when it touches the inner limit.
    const double r = static_cast<double>(rmin) - 0.5;
    b.has_distance = false;
    b.distance = 0.0;
    if (imin < 0 || r <= map_.min_radius() + 1.0) return;
    if (const auto d = map_.ground_distance(r, bearing_[static_cast<std::size_t>(imin)])) {
      b.distance = *d;
      b.has_distance = true;
    }
  };

  cv::Mat mask, labels, stats, centroids;
  for (const ColourClass colour : p_.colours) {
    if (bx1[colour] < 0) continue;  // no pixel of this colour
    const cv::Rect roi(bx0[colour], by0[colour], bx1[colour] - bx0[colour] + 1, by1[colour] - by0[colour] + 1);
    cv::compare(cls(roi), cv::Scalar(colour), mask, cv::CMP_EQ);
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    const bool edges = std::find(p_.edge_colours.begin(), p_.edge_colours.end(), colour) != p_.edge_colours.end();
    for (int k = 1; k < n; ++k) {
      const int area = stats.at<int>(k, cv::CC_STAT_AREA);
      if (area < p_.min_area_px) continue;
      // Image coordinates = ROI coordinates + (ox, oy).
      const int ox = roi.x, oy = roi.y;
      const int x0 = stats.at<int>(k, cv::CC_STAT_LEFT), y0 = stats.at<int>(k, cv::CC_STAT_TOP);
      const int x1 = x0 + stats.at<int>(k, cv::CC_STAT_WIDTH), y1 = y0 + stats.at<int>(k, cv::CC_STAT_HEIGHT);
      Region g;
      g.ref = std::atan2(-(centroids.at<double>(k, 0) + ox + 0.5 - c.x()), -(centroids.at<double>(k, 1) + oy + 0.5 - c.y()));
      g.dmin = std::numeric_limits<double>::max();
      g.dmax = std::numeric_limits<double>::lowest();
      for (int v = y0; v < y1; ++v) {
        const int* lab = labels.ptr<int>(v);
        for (int u = x0; u < x1; ++u) {
          if (lab[u] != k) continue;
          const std::size_t i = static_cast<std::size_t>(v + oy) * w_ + (u + ox);
          const double d = wrap_angle(bearing_[i] - g.ref);
          const double half = p_.edge_extend_px / radius_[i];  // pixels to radians at this radius
          g.dmin = std::min(g.dmin, d - half);
          g.dmax = std::max(g.dmax, d + half);
          if (radius_[i] < g.rmin) {
            g.rmin = radius_[i];
            g.imin = static_cast<int>(i);
          }
          g.rmax = std::max(g.rmax, radius_[i]);
        }
      }
      Blob b;
      b.colour = colour;
      b.kind = Blob::Kind::kRegion;
      b.left_bearing = wrap_angle(g.ref + g.dmax);
      b.right_bearing = wrap_angle(g.ref + g.dmin);
      b.bearing = wrap_angle(g.ref + 0.5 * (g.dmin + g.dmax));
      b.area_px = area;
      b.left_occluded = occluded(g.ref + g.dmax, +1, g);
      b.right_occluded = occluded(g.ref + g.dmin, -1, g);
      contact(b, g.rmin, g.imin);
      out.push_back(b);
      if (!edges) continue;
      // Nearest pixels close to each edge give the edges' distances.
      const double band = deg2rad(p_.edge_contact_deg);
      float rl = std::numeric_limits<float>::max(), rr = rl;
      int il = -1, ir = -1;
      for (int v = y0; v < y1; ++v) {
        const int* lab = labels.ptr<int>(v);
        for (int u = x0; u < x1; ++u) {
          if (lab[u] != k) continue;
          const std::size_t i = static_cast<std::size_t>(v + oy) * w_ + (u + ox);
          const double d = wrap_angle(bearing_[i] - g.ref);
          if (d >= g.dmax - band && radius_[i] < rl) {
            rl = radius_[i];
            il = static_cast<int>(i);
          }
          if (d <= g.dmin + band && radius_[i] < rr) {
            rr = radius_[i];
            ir = static_cast<int>(i);
          }
        }
      }
      Blob left = b, right = b;
      left.kind = Blob::Kind::kLeftEdge;
      left.bearing = b.left_bearing;
      contact(left, rl, il);
      right.kind = Blob::Kind::kRightEdge;
      right.bearing = b.right_bearing;
      contact(right, rr, ir);
      out.push_back(left);
      out.push_back(right);
    }
  }
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) {
    if (a.colour != b.colour) return a.colour < b.colour;
    if (a.kind != b.kind) return a.kind < b.kind;
    return a.bearing < b.bearing;
  });
  return out;
}

}  // namespace omniloc
