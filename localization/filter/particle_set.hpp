#pragma once
// The particle set and the operations every particle filter of omniloc shares: weights from
// log-likelihoods, the effective sample size, and low-variance (systematic) resampling. Users: MCL
// (localization/mcl.*, states are world-frame poses) and paper 001's filters
// (localization/cooperative/particle_core.hpp, ball states and the scalar growth model).
// KLD-adaptive sample sizes are in kld.hpp, the odometry motion noise in odometry_noise.hpp.
//
// Weights carry no unit. They need not be normalised: every function here says whether it takes the
// sum as given or divides by it. Keeping them unnormalised where possible matters: dividing first
// changes the cumulative sums in their last bits, and with them which particle a pointer lands on.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <vector>

#include "core/rng.hpp"

namespace omniloc::filter {

/// N states with one weight each. S is any copyable state (a Pose2, a ball's Eigen::Vector4d, a double).
template <class S>
struct ParticleSet {
  std::vector<S> x;
  std::vector<double> w;  ///< not necessarily normalised (paper 001's MFBPF keeps S_k = sum w explicit)
  std::size_t size() const { return x.size(); }
};

/// Sum of the weights, added in index order (the order fixes the result's last bits).
inline double weight_sum(const std::vector<double>& w) { return std::accumulate(w.begin(), w.end(), 0.0); }

/// Effective sample size N_eff = (sum w)^2 / sum w^2, equal to 1 / sum w~^2 for normalised w~
/// (Kong, Liu, Wong 1994; paper 001 5.2 step 3). N for uniform weights, 1 when one particle holds
/// all the mass, 0 for an empty or all-zero set.
inline double effective_sample_size(const std::vector<double>& w) {
  double s = 0.0, s2 = 0.0;
  for (double v : w) {
    s += v;
    s2 += v * v;
  }
  return s2 > 0.0 ? s * s / s2 : 0.0;
}

/// Divides by the sum; a zero, negative or non-finite sum gives uniform weights 1/N instead (nothing
/// downstream then sees a NaN).
inline void normalise(std::vector<double>& w) {
  const double s = weight_sum(w);
  if (!(s > 0.0) || !std::isfinite(s)) {
    std::fill(w.begin(), w.end(), 1.0 / static_cast<double>(w.size()));
    return;
  }
  for (double& v : w) v /= s;
}

/// Weights from log-weights: w_i = exp(lw_i - max_j lw_j). Subtracting the maximum multiplies every
/// weight by one constant, so the normalised weights, N_eff and every resampling decision are those
/// of exp(lw_i), but a sharp likelihood (hundreds of points) cannot underflow every weight to zero.
/// Returns the maximum; when it is not finite (every log-weight -inf or NaN) w is set to 1/N.
inline double weights_from_log(const std::vector<double>& lw, std::vector<double>& w) {
  double mx = -std::numeric_limits<double>::infinity();
  for (double l : lw) mx = std::max(mx, l);
  w.resize(lw.size());
  if (!std::isfinite(mx)) {
    std::fill(w.begin(), w.end(), 1.0 / static_cast<double>(w.size()));
    return mx;
  }
  for (std::size_t i = 0; i < lw.size(); ++i) w[i] = std::exp(lw[i] - mx);
  return mx;
}

/// Low-variance (systematic) resampling, Thrun, Burgard, Fox, Probabilistic Robotics (2005), table
/// 4.4: one uniform draw u0 in [0, sum / n) and n pointers u0 + m sum / n into the cumulative weights.
/// O(N + n), and a particle of weight w gets floor(n w / sum) or one more copies: far less variance
/// than n independent draws, and the set survives unchanged when the weights are uniform.
///
/// index(m) gives the particle pointer m lands on. Pointers must be asked for in increasing m, but may
/// be skipped: MCL's augmented variant (random injection) fills some slots with new particles and the
/// remaining slots keep the pointers they would have had.
class LowVarianceSampler {
 public:
  /// `w`: weights (not copied: must outlive the sampler), `sum`: their total as the caller computed
  /// it (1 for normalised weights), `n`: number of pointers. Draws u0 from `rng` (one uniform).
  LowVarianceSampler(const std::vector<double>& w, double sum, std::size_t n, Rng& rng)
      : w_(w), step_(sum / static_cast<double>(n)), u0_(rng.uniform() * step_), acc_(w.empty() ? 0.0 : w[0]) {}

  /// Index of the particle pointer m (0 <= m < n) falls on.
  std::size_t index(std::size_t m) {
    const double target = u0_ + static_cast<double>(m) * step_;
    while (acc_ < target && i_ + 1 < w_.size()) acc_ += w_[++i_];
    return i_;
  }
  /// Spacing of the pointers (sum / n).
  double step() const { return step_; }

 private:
  const std::vector<double>& w_;
  double step_, u0_, acc_;
  std::size_t i_ = 0;
};

/// Systematic resampling of a whole set: normalises, draws N particles with LowVarianceSampler, and
/// leaves every weight at 1/N (paper 001's bootstrap and fission filters).
template <class S>
void systematic_resample(ParticleSet<S>& p, Rng& rng) {
  const std::size_t n = p.size();
  normalise(p.w);
  std::vector<S> out;
  out.reserve(n);
  LowVarianceSampler sampler(p.w, 1.0, n, rng);
  for (std::size_t m = 0; m < n; ++m) out.push_back(p.x[sampler.index(m)]);
  p.x = std::move(out);
  std::fill(p.w.begin(), p.w.end(), sampler.step());
}

}  // namespace omniloc::filter
