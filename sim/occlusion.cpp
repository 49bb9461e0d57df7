#include "sim/occlusion.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/angles.hpp"
#include "core/error.hpp"

namespace omniloc::sim {

namespace {
// More black sectors than this make no sense on a 360-degree panorama of a few hundred pixels round.
constexpr std::size_t kMaxSectors = 360;
}  // namespace

double OcclusionMask::fraction() const {
  double w = 0;
  for (const auto& s : sectors) w += s.width;
  return std::min(1.0, w / kTwoPi);
}

std::vector<Sector> OcclusionMask::robot_frame(double theta) const {
  if (!world_fixed) return sectors;
  std::vector<Sector> out = sectors;
  for (auto& s : out) s.start = wrap_angle_positive(s.start - theta);
  return out;
}

OcclusionMask OcclusionMask::from_json(const Json& j, const std::string& path) {
  JsonReader r(j, path);
  r.allow("comment");
  OcclusionMask m;
  m.world_fixed = r.string("frame", std::string("robot"), {"robot", "world"}) == "world";
  const Json* sj = r.raw("sectors");
  if (sj && sj->is_array()) {
    const std::string sp = r.child_path("sectors");
    for (std::size_t i = 0; i < sj->size(); ++i) {
      const Json& e = (*sj)[i];
      if (!e.is_array() || e.size() != 2 || !e[0].is_number() || !e[1].is_number() || e[1].get<double>() <= 0 || e[1].get<double>() > 360)
        throw ConfigError(json_child(sp, i), json_brief(e), "a sector [start_deg, width_deg] with 0 < width <= 360");
      m.sectors.push_back({wrap_angle_positive(deg2rad(e[0].get<double>())), deg2rad(e[1].get<double>())});
    }
    // Overlap check on the circle, in O(n log n): sorted by start, a sector can only overlap the
    // sectors after it by also overlapping its next neighbour (whose start lies between), so
    // comparing each sector with its circular successor finds every overlap. (The pairwise check
    // took 34 s for 100000 sectors; the count is also capped, since painting is per sector.)
    if (m.sectors.size() > kMaxSectors)
      throw ConfigError(sp, "an array of " + std::to_string(m.sectors.size()) + " sectors",
                        "at most " + std::to_string(kMaxSectors) + " sectors");
    std::vector<std::size_t> order(m.sectors.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return m.sectors[x].start < m.sectors[y].start; });
    for (std::size_t k = 0; order.size() > 1 && k < order.size(); ++k) {
      const std::size_t a = order[k], b = order[(k + 1) % order.size()];
      const double off = wrap_angle_positive(m.sectors[b].start - m.sectors[a].start);
      if (off < m.sectors[a].width - 1e-9) {
        const std::size_t later = std::max(a, b), earlier = std::min(a, b);
        throw ConfigError(json_child(sp, later), json_brief((*sj)[later]), "sectors that do not overlap (it overlaps sector " + std::to_string(earlier) + ")");
      }
    }
  } else {
    const double f = r.number("fraction", std::nullopt, 0.0, 1.0);
    const long long n = sj ? r.integer("sectors", 1, 1, 36) : 1;
    const double start = deg2rad(r.number("start_deg", 0.0, -360.0, 360.0));
    if (f > 0)
      for (long long k = 0; k < n; ++k)
        m.sectors.push_back({wrap_angle_positive(start + k * kTwoPi / n), f * kTwoPi / n});
  }
  r.finish();
  return m;
}

void paint_sectors(Image& image, const Eigen::Vector2d& c, const std::vector<Sector>& sectors) {
  if (sectors.empty()) return;
  // The bearing of every pixel depends only on the image size and centre: computed once per thread
  // and reused (one atan2 per pixel was 20-40 ms of a 640 x 640 frame, four times the rendering).
  // The same double per pixel as before, so the painted pixels are byte-identical.
  struct Bearings {
    int width = -1, height = -1;
    Eigen::Vector2d centre{NAN, NAN};
    std::vector<double> b;
  };
  thread_local Bearings cache;
  if (cache.width != image.width || cache.height != image.height || cache.centre != c) {
    cache.width = image.width;
    cache.height = image.height;
    cache.centre = c;
    cache.b.resize(static_cast<std::size_t>(image.width) * image.height);
    for (int v = 0; v < image.height; ++v)
      for (int u = 0; u < image.width; ++u) {
        const double du = u + 0.5 - c.x(), dv = v + 0.5 - c.y();
        // Inverse of image_direction: forward = -v, left = -u.
        cache.b[static_cast<std::size_t>(v) * image.width + u] = wrap_angle_positive(std::atan2(-du, -dv));
      }
  }
  for (int v = 0; v < image.height; ++v) {
    std::uint8_t* row = image.row(v);
    const double* bearing = cache.b.data() + static_cast<std::size_t>(v) * image.width;
    for (int u = 0; u < image.width; ++u) {
      for (const auto& s : sectors) {
        // wrap_angle_positive without its fmod where |d| < 2 pi (there fmod returns d exactly).
        double d = bearing[u] - s.start;
        if (d >= kTwoPi || d <= -kTwoPi) d = std::fmod(d, kTwoPi);
        if (d < 0.0) d += kTwoPi;
        if (d < s.width) {
          row[3 * u] = row[3 * u + 1] = row[3 * u + 2] = 0;
          break;
        }
      }
    }
  }
}

}  // namespace omniloc::sim
