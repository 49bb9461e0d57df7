#pragma once
// Shared particle-filter machinery for the ball trackers and the growth-model benchmark of paper 001
// (Xu, Xie, Wang, Ni, J. Image and Graphics 2012, section 5): bootstrap PF with systematic
// resampling, the fission bootstrap PF (FBPF, section 5.1, after Cheng and Zhang 2008, the paper's
// ref. [9]) and the paper's modified FBPF (MFBPF, section 5.2). Templated on the state type so the
// 4-D ball tracker and the scalar benchmark run the very same code; S must support S + S, S * double
// and value initialisation from the first particle (double and Eigen vectors do).
//
// A filter cycle is: predict() -> update() -> (read the weighted estimate) -> post(). The estimate is
// read before post() because the paper outputs it before SFN / resampling (5.1 step 3, 5.2 step 2).
//
// Weights are handled in the log domain and rescaled by their maximum before exponentiating
// (filter::weights_from_log); this multiplies every weight by the same constant, so N_eff, the
// normalised weights and every decision below are unchanged, but a sharp likelihood cannot underflow
// all weights to zero.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <vector>

#include "core/rng.hpp"
#include "localization/filter/particle_set.hpp"

namespace omniloc {

/// Which of paper 001's particle filters.
enum class ParticleFilterKind {
  Bootstrap,        ///< SIS with weights carried over, systematic resampling when N_eff < N_th
  Fission,          ///< FBPF (5.1): w = p(y|x); SFN when N_eff < N_th; then systematic resampling
  ModifiedFission,  ///< MFBPF (5.2): w = w_prev p(y|x); SFN when N_eff >= N_th, else overwrite light by heavy
};

const char* to_string(ParticleFilterKind k);

namespace pfcore {

// The set, weights, N_eff and systematic resampling are the ones MCL uses (filter/particle_set.hpp).
using filter::effective_sample_size;
using filter::normalise;
using filter::ParticleSet;
using filter::systematic_resample;
using filter::weight_sum;

/// What post() did (for diagnostics and tests).
struct PostInfo {
  bool resampled = false;  ///< systematic or overwrite resampling ran
  bool fission = false;    ///< SFN pre-processing ran
};

/// Indices sorted by weight, heaviest first; ties keep index order (deterministic everywhere).
inline std::vector<std::size_t> order_heaviest_first(const std::vector<double>& w) {
  std::vector<std::size_t> idx(w.size());
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::stable_sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return w[a] > w[b]; });
  return idx;
}

/// Weighted mean of the set (sum w x / sum w, paper 001 5.2 step 2).
template <class S>
S weighted_mean(const ParticleSet<S>& p) {
  const double s = weight_sum(p.w);
  const double n = static_cast<double>(p.size());
  S m = p.x[0] * (s > 0.0 ? p.w[0] / s : 1.0 / n);
  for (std::size_t i = 1; i < p.size(); ++i) m = m + p.x[i] * (s > 0.0 ? p.w[i] / s : 1.0 / n);
  return m;
}

/// Draw every particle from p(x_k | x_{k-1}) (paper 001 5.1 / 5.2 step 1).
template <class S, class Propagate>
void predict(ParticleSet<S>& p, Propagate&& propagate, Rng& rng) {
  for (S& s : p.x) propagate(s, rng);
}

/// Weight update with log-likelihood log p(y | x). FBPF uses w = p(y|x) (5.1 step 1: its set is
/// uniform after the previous resampling anyway); Bootstrap and MFBPF use w = w_prev p(y|x).
/// Returns false when every weight vanished (all likelihoods zero / non-finite): the weights are then
/// reset to uniform, so nothing downstream sees a NaN.
template <class S, class LogLik>
bool update(ParticleFilterKind kind, ParticleSet<S>& p, LogLik&& loglik) {
  const std::size_t n = p.size();
  std::vector<double> lw(n);
  for (std::size_t i = 0; i < n; ++i) {
    double l = loglik(p.x[i]);
    if (std::isnan(l)) l = -std::numeric_limits<double>::infinity();
    if (kind != ParticleFilterKind::Fission)
      l += p.w[i] > 0.0 ? std::log(p.w[i]) : -std::numeric_limits<double>::infinity();
    lw[i] = l;
  }
  return std::isfinite(filter::weights_from_log(lw, p.w));
}

/// SFN pre-processing (paper 001 5.1 step 5, after its ref. [9]): Sorting, Fission, Normalising.
/// - Sort by weight, heaviest first.
/// - Fission: a heavy particle (normalised weight w > 1/N) splits into n = floor(N w) offspring: itself
///   plus n - 1 copies displaced by `jitter` (the paper's "fission variance"); each offspring carries
///   w / n, so the represented distribution keeps its mass.
/// - The slots left over are given to the next-heaviest remaining particles unchanged; the lightest
///   particles that find no slot are discarded.
/// - Normalise.
/// `child` (optional, size N on return) marks the displaced offspring.
template <class S, class Jitter>
void sfn(ParticleSet<S>& p, Jitter&& jitter, Rng& rng, std::vector<bool>* child = nullptr) {
  const std::size_t n = p.size();
  normalise(p.w);
  const std::vector<std::size_t> order = order_heaviest_first(p.w);
  const double nd = static_cast<double>(n);
  std::vector<S> xs;
  std::vector<double> ws;
  std::vector<bool> is_child;
  xs.reserve(n);
  ws.reserve(n);
  is_child.reserve(n);
  std::size_t k = 0;
  for (; k < n && xs.size() < n; ++k) {
    const std::size_t i = order[k];
    if (!(p.w[i] * nd > 1.0)) break;  // the rest are not heavy
    const std::size_t room = n - xs.size();
    const std::size_t m = std::min(room, std::max<std::size_t>(1, static_cast<std::size_t>(std::floor(p.w[i] * nd))));
    const double share = p.w[i] / static_cast<double>(m);
    xs.push_back(p.x[i]);
    ws.push_back(share);
    is_child.push_back(false);
    for (std::size_t c = 1; c < m; ++c) {
      S s = p.x[i];
      jitter(s, rng);
      xs.push_back(s);
      ws.push_back(share);
      is_child.push_back(true);
    }
  }
  for (; k < n && xs.size() < n; ++k) {  // fill with the next-heaviest, unchanged
    xs.push_back(p.x[order[k]]);
    ws.push_back(p.w[order[k]]);
    is_child.push_back(false);
  }
  p.x = std::move(xs);
  p.w = std::move(ws);
  normalise(p.w);
  if (child) *child = std::move(is_child);
}

/// MFBPF resampling (paper 001 5.2 step 5): "copy the heavy particles over the light ones".
/// Heavy = normalised weight > 1/N; a heavy particle keeps itself and is copied floor(N w) - 1 more
/// times over light particles (heaviest first); light slots still left are overwritten by the heavy
/// particles in turn, heaviest first. Copies are exact (no jitter). All weights become 1/N.
/// If no particle is heavy (uniform weights) nothing moves.
template <class S>
void overwrite_resample(ParticleSet<S>& p) {
  const std::size_t n = p.size();
  normalise(p.w);
  const std::vector<std::size_t> order = order_heaviest_first(p.w);
  const double nd = static_cast<double>(n);
  std::size_t heavy = 0;
  while (heavy < n && p.w[order[heavy]] * nd > 1.0) ++heavy;
  if (heavy > 0) {
    std::vector<S> xs;
    xs.reserve(n);
    for (std::size_t h = 0; h < heavy; ++h) xs.push_back(p.x[order[h]]);
    for (std::size_t h = 0; h < heavy && xs.size() < n; ++h) {
      const auto extra = static_cast<std::size_t>(std::floor(p.w[order[h]] * nd)) - 1;
      for (std::size_t c = 0; c < extra && xs.size() < n; ++c) xs.push_back(p.x[order[h]]);
    }
    for (std::size_t h = 0; xs.size() < n; h = (h + 1) % heavy) xs.push_back(p.x[order[h]]);
    p.x = std::move(xs);
  }
  std::fill(p.w.begin(), p.w.end(), 1.0 / nd);
}

/// Resampling / fission after an update with an observation, by kind. `threshold` is N_th / N_s.
template <class S, class Jitter>
PostInfo post(ParticleFilterKind kind, ParticleSet<S>& p, double threshold, Jitter&& jitter, Rng& rng) {
  PostInfo info;
  const double n_eff = effective_sample_size(p.w);
  const double n_th = threshold * static_cast<double>(p.size());
  switch (kind) {
    case ParticleFilterKind::Bootstrap:
      if (n_eff < n_th) {
        systematic_resample(p, rng);
        info.resampled = true;
      } else {
        normalise(p.w);
      }
      break;
    case ParticleFilterKind::Fission:
      // 5.1 steps 4-6: SFN when the weights are sharp, then resampling every cycle.
      if (n_eff < n_th) {
        sfn(p, jitter, rng);
        info.fission = true;
      }
      systematic_resample(p, rng);
      info.resampled = true;
      break;
    case ParticleFilterKind::ModifiedFission: {
      // 5.2 steps 4-5: SFN when N_eff >= N_th with the new fission particles' weights set to 1/N_s
      // (the others keep their normalised weight); otherwise overwrite light by heavy.
      if (n_eff >= n_th) {
        std::vector<bool> child;
        sfn(p, jitter, rng, &child);
        const double u = 1.0 / static_cast<double>(p.size());
        for (std::size_t i = 0; i < p.size(); ++i)
          if (child[i]) p.w[i] = u;
        info.fission = true;
      } else {
        overwrite_resample(p);
        info.resampled = true;
      }
      break;
    }
  }
  return info;
}

}  // namespace pfcore
}  // namespace omniloc
