#include "localization/filter/kld.hpp"

#include <cmath>

#include "core/angles.hpp"

namespace omniloc::filter {

const ParamList<KldParams>& KldParams::params() {
  using P = KldParams;
  static const ParamList<P> list = {
      bool_param("kld", &P::enabled, "KLD-adaptive sample size (Fox 2003); the particle count is then the maximum"),
      positive_param("kld_epsilon", &P::epsilon, 1.0, "", "bound on the KL distance (Fox 2003's epsilon; amcl pf_err 0.05)"),
      positive_param("kld_z", &P::z, 10.0, "", "upper standard-normal quantile z_(1-delta); 2.326: delta = 0.01 (amcl pf_z 0.99)"),
      positive_param("kld_bin_xy", &P::bin_xy, 10.0, "m", "histogram bin in x and y (amcl: 0.5 m)"),
      positive_param("kld_bin_theta", &P::bin_theta, 3.2, "rad", "histogram bin in heading (amcl: 10 degrees)"),
      integer_param("kld_min_particles", &P::min_particles, 1, 100000, "never fewer particles"),
  };
  return list;
}

KldParams KldParams::from_json(JsonReader& r) {
  KldParams p;
  read_params(r, p, params());
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
