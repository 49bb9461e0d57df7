#include "localization/filter/kld.hpp"

#include <cmath>

#include "core/angles.hpp"

namespace omniloc::filter {

KldParams KldParams::from_json(JsonReader& r) {
  KldParams p;
  p.enabled = r.boolean("kld", p.enabled);
  p.epsilon = r.positive("kld_epsilon", p.epsilon, 1.0);
  p.z = r.positive("kld_z", p.z, 10.0);
  p.bin_xy = r.positive("kld_bin_xy", p.bin_xy, 10.0);
  p.bin_theta = r.positive("kld_bin_theta", p.bin_theta, 3.2);
  p.min_particles = static_cast<int>(r.integer("kld_min_particles", p.min_particles, 1, 100000));
  return p;
}

double kld_bound(std::size_t k, double epsilon, double z) {
  if (k <= 1) return 0.0;
  const double km1 = static_cast<double>(k) - 1;
  const double a = 2.0 / (9.0 * km1);
  return km1 / (2 * epsilon) * std::pow(1 - a + std::sqrt(a) * z, 3);
}

bool KldHistogram::insert(const Pose2& q) {
  // 20 bits per axis: bins of 0.5 m cover +-262 km, far beyond any field; two's-complement masking
  // keeps negative bin numbers distinct.
  const auto bx = static_cast<std::int64_t>(std::floor(q.x / bin_xy_)), by = static_cast<std::int64_t>(std::floor(q.y / bin_xy_));
  const auto bt = static_cast<std::int64_t>(std::floor(wrap_angle(q.theta) / bin_theta_));
  return bins_
      .insert((static_cast<std::uint64_t>(bx & 0xFFFFF) << 40) | (static_cast<std::uint64_t>(by & 0xFFFFF) << 20) |
              static_cast<std::uint64_t>(bt & 0xFFFFF))
      .second;
}

}  // namespace omniloc::filter
