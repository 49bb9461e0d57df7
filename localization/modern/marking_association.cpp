#include "localization/modern/marking_association.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace omniloc::modern {

MarkingAssociation::MarkingAssociation(const Field& field, double cell, double reach) : segments_(field.segments), arcs_(field.arcs) {
  const double hx = field.half_floor_x() + reach, hy = field.half_floor_y() + reach;
  inv_cell_ = 1.0 / cell;
  nx_ = static_cast<int>(std::ceil(2 * hx / cell));
  ny_ = static_cast<int>(std::ceil(2 * hy / cell));
  x0_ = -hx;
  y0_ = -hy;
  nearest_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), {-1, -1, -1});
  const int m = markings();
  std::vector<std::pair<double, int>> d(static_cast<std::size_t>(m));
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) {
      const Eigen::Vector2d c(x0_ + (i + 0.5) * cell, y0_ + (j + 0.5) * cell);
      for (int k = 0; k < m; ++k) d[static_cast<std::size_t>(k)] = {distance(k, c), k};
      const std::size_t keep = std::min<std::size_t>(3, d.size());
      std::partial_sort(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(keep), d.end());
      auto& slot = nearest_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)];
      for (std::size_t q = 0; q < keep; ++q) slot[q] = static_cast<std::int16_t>(d[q].second);
    }
}

double MarkingAssociation::distance(int k, const Eigen::Vector2d& w) const {
  const auto ns = static_cast<int>(segments_.size());
  if (k < ns) return distance_to_segment(w, segments_[static_cast<std::size_t>(k)].a, segments_[static_cast<std::size_t>(k)].b);
  return distance_to_arc(w, arcs_[static_cast<std::size_t>(k - ns)]);
}

LocalMarking MarkingAssociation::associate(const Eigen::Vector2d& w) const {
  const int i = static_cast<int>(std::floor((w.x() - x0_) * inv_cell_)), j = static_cast<int>(std::floor((w.y() - y0_) * inv_cell_));
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  if (i >= 0 && j >= 0 && i < nx_ && j < ny_) {
    for (std::int16_t k : nearest_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)]) {
      if (k < 0) continue;
      const double d = distance(k, w);
      if (d < best_d) best_d = d, best = k;
    }
  } else {
    for (int k = 0; k < markings(); ++k) {
      const double d = distance(k, w);
      if (d < best_d) best_d = d, best = k;
    }
  }
  if (best < 0) return {};
  return local(best, w);
}

LocalMarking MarkingAssociation::local(int k, const Eigen::Vector2d& w) const {
  LocalMarking m;
  m.marking = k;
  const auto ns = static_cast<int>(segments_.size());
  // A point beyond a marking's end measures its distance to that end: the line through the end
  // point, normal to the direction from it (tangent to the circle of that distance).
  const auto to_end = [&](const Eigen::Vector2d& e) {
    const Eigen::Vector2d v = w - e;
    const double len = v.norm();
    m.n = len > 1e-9 ? Eigen::Vector2d(v / len) : Eigen::Vector2d(1.0, 0.0);
    m.offset = m.n.dot(e);
    m.distance = len;
  };
  if (k < ns) {
    const auto& s = segments_[static_cast<std::size_t>(k)];
    const Eigen::Vector2d ab = s.b - s.a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? (w - s.a).dot(ab) / len2 : 0.0;
    if (t < 0) to_end(s.a);
    else if (t > 1) to_end(s.b);
    else {
      Eigen::Vector2d n(-ab.y(), ab.x());
      n.normalize();
      if (n.dot(w - s.a) < 0) n = -n;
      m.n = n;
      m.offset = n.dot(s.a);
      m.distance = n.dot(w - s.a);
    }
    return m;
  }
  const auto& a = arcs_[static_cast<std::size_t>(k - ns)];
  const Eigen::Vector2d d = w - a.centre;
  const double r = d.norm();
  const bool full = a.sweep >= kTwoPi - 1e-12;
  const double ang = wrap_angle_positive(std::atan2(d.y(), d.x()) - a.start);
  if (r > 0 && (full || ang <= a.sweep)) {
    m.circle = true;
    m.centre = a.centre;
    m.radius = a.radius;
    m.sign = r >= a.radius ? 1.0 : -1.0;
    m.distance = std::fabs(r - a.radius);
    return m;
  }
  const Eigen::Vector2d e0 = a.centre + a.radius * Eigen::Vector2d(std::cos(a.start), std::sin(a.start));
  const double a1 = a.start + a.sweep;
  const Eigen::Vector2d e1 = a.centre + a.radius * Eigen::Vector2d(std::cos(a1), std::sin(a1));
  to_end((w - e0).squaredNorm() <= (w - e1).squaredNorm() ? e0 : e1);
  return m;
}

}  // namespace omniloc::modern
