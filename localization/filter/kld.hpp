#pragma once
// KLD-adaptive sample size (Fox, "Adapting the sample size in particle filters through KLD-sampling",
// IJRR 22(12), 2003; the same scheme as ROS amcl's pf_err / pf_z). Particles are drawn one at a time
// and the histogram bins of (x, y, theta) they fall into are counted; drawing stops once the number
// drawn bounds the Kullback-Leibler distance between the sample-based and the true posterior by
// epsilon with probability 1 - delta. A set spread over the field fills many bins and keeps (nearly)
// the maximum; a converged set fills a few and shrinks towards min_particles, saving sensor-model
// work where it is not needed.
//
// Units: bin_xy in metres, bin_theta in radians, poses in the world frame.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/pose2.hpp"
#include "core/rng.hpp"

namespace omniloc::filter {

struct KldParams {
  bool enabled = false;      ///< off by default: the fixed-size set of paper 002 (JSON "kld")
  double epsilon = 0.05;     ///< bound on the KL distance (Fox 2003's epsilon; amcl pf_err 0.05)
  double z = 2.326;          ///< upper standard-normal quantile z_{1-delta}; 2.326: delta = 0.01 (amcl pf_z 0.99)
  double bin_xy = 0.5;       ///< m, histogram bin in x and y (amcl: 0.5 m)
  double bin_theta = 0.1745; ///< rad, histogram bin in heading (amcl: 10 degrees)
  int min_particles = 100;   ///< never fewer (the bound is meaningless for k = 1 bin)
  /// Reads the flat keys kld, kld_epsilon, kld_z, kld_bin_xy, kld_bin_theta, kld_min_particles.
  static KldParams from_json(JsonReader& r);
  static const ParamList<KldParams>& params();
};

/// Fox 2003 (the KLD bound): the number of particles n such that, with probability 1 - delta, the KL
/// distance between the maximum-likelihood estimate over k non-empty bins and the true distribution
/// is below epsilon: n = chi^2_{k-1, 1-delta} / (2 epsilon), with the chi-square quantile by the
/// Wilson-Hilferty approximation:
///   n = (k - 1) / (2 epsilon) * (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z_{1-delta})^3.
/// Defined for k >= 2 (chi-square with k - 1 degrees of freedom); returns 0 for k <= 1.
double kld_bound(std::size_t k, double epsilon, double z);

/// The set of (x, y, theta) histogram bins that particles fell into.
class KldHistogram {
 public:
  KldHistogram(double bin_xy, double bin_theta) : bin_xy_(bin_xy), bin_theta_(bin_theta) {}
  /// Counts the bin of `q` (heading wrapped to (-pi, pi] first). Returns true if the bin was new.
  bool insert(const Pose2& q);
  std::size_t bins() const { return bins_.size(); }

 private:
  double bin_xy_, bin_theta_;
  std::unordered_set<std::uint64_t> bins_;
};

/// KLD resampling: draws indices into the set one at a time, independently and in proportion to
/// `w` (total `sum`, one rng.uniform(0, sum) per draw), until the count reaches both
/// p.min_particles and kld_bound(bins, ...), or max_n. While every draw has fallen into one bin the
/// bound is undefined and drawing goes on (ROS amcl likewise takes the maximum for one bin): a set
/// that narrow has collapsed, and a full set gives the motion noise the most room to spread it
/// again. `pose_of(i)` gives particle i's pose. Returns the drawn indices in order of drawing.
template <class PoseOf>
std::vector<std::size_t> kld_resample(const std::vector<double>& w, double sum, int max_n, const KldParams& p, PoseOf&& pose_of,
                                      Rng& rng) {
  std::vector<double> cum(w.size());
  double acc = 0;
  for (std::size_t i = 0; i < w.size(); ++i) cum[i] = (acc += w[i]);
  std::vector<std::size_t> drawn;
  KldHistogram hist(p.bin_xy, p.bin_theta);
  for (int m = 0; m < max_n; ++m) {
    const double u = rng.uniform(0, sum);
    const auto i = std::min(w.size() - 1, static_cast<std::size_t>(std::lower_bound(cum.begin(), cum.end(), u) - cum.begin()));
    drawn.push_back(i);
    hist.insert(pose_of(i));
    if (hist.bins() > 1 && static_cast<int>(drawn.size()) >= p.min_particles &&
        static_cast<double>(drawn.size()) >= kld_bound(hist.bins(), p.epsilon, p.z))
      break;
  }
  return drawn;
}

}  // namespace omniloc::filter
