#include <cmath>

#include "sim/world_state.hpp"

namespace omniloc::sim {

double Lighting::artificial_at(const Eigen::Vector2d& p) const {
  if (lamps.empty()) return level;
  double on = 0.0, all = 0.0, states = 0.0;
  for (const auto& l : lamps) {
    const double k = std::exp(-(p - l.centre).squaredNorm() / (2.0 * l.spread * l.spread));
    on += l.state * k;
    all += k;
    states += l.state;
  }
  const double mean_state = states / static_cast<double>(lamps.size());
  // Far outside every lamp's footprint the kernels underflow: the mean state is the limit there.
  const double direct = all > 1e-200 ? on / all : mean_state;
  return level * ((1.0 - diffuse) * direct + diffuse * mean_state);
}

double Lighting::at(const Eigen::Vector2d& p) const {
  double e = artificial_at(p);
  for (const auto& s : sun)
    if (s.surface == SunPatch::Surface::kFloor && std::fabs(p.x() - s.centre.x()) <= s.half_size.x() &&
        std::fabs(p.y() - s.centre.y()) <= s.half_size.y())
      e += s.strength;
  return e;
}

}  // namespace omniloc::sim
