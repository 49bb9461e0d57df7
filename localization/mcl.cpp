#include "localization/mcl.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_set>

#include "localization/matching.hpp"

namespace omniloc {

McLParams McLParams::from_json(JsonReader& r) {
  McLParams p;
  p.particles = static_cast<int>(r.integer("particles", p.particles, 10, 100000));
  p.sigma = r.positive("sigma", p.sigma, 5.0);
  p.clamp = r.positive("clamp", p.clamp, 10.0);
  p.max_points = static_cast<int>(r.integer("max_points", p.max_points, 1, 10000));
  p.min_points = static_cast<int>(r.integer("min_points", p.min_points, 1, 10000));
  p.evidence_points = r.number("evidence_points", p.evidence_points, 0.0, 10000.0);
  p.heading_sigma = r.positive("heading_sigma", p.heading_sigma, 10.0);
  p.odo_trans_frac = r.number("odo_trans_frac", p.odo_trans_frac, 0.0, 2.0);
  p.odo_rot_frac = r.number("odo_rot_frac", p.odo_rot_frac, 0.0, 2.0);
  p.odo_floor_xy = r.number("odo_floor_xy", p.odo_floor_xy, 0.0, 1.0);
  p.odo_floor_theta = r.number("odo_floor_theta", p.odo_floor_theta, 0.0, 1.0);
  p.converged_std = r.positive("converged_std", p.converged_std, 10.0);
  p.converged_theta_std = r.positive("converged_theta_std", p.converged_theta_std, 10.0);
  p.alpha_slow = r.number("alpha_slow", p.alpha_slow, 0.0, 1.0);
  p.alpha_fast = r.number("alpha_fast", p.alpha_fast, 0.0, 1.0);
  p.cell = r.number("cell", p.cell, 0.005, 0.5);
  p.kld = r.boolean("kld", p.kld);
  p.kld_epsilon = r.positive("kld_epsilon", p.kld_epsilon, 1.0);
  p.kld_z = r.positive("kld_z", p.kld_z, 10.0);
  p.kld_bin_xy = r.positive("kld_bin_xy", p.kld_bin_xy, 10.0);
  p.kld_bin_theta = r.positive("kld_bin_theta", p.kld_bin_theta, 3.2);
  p.kld_min_particles = static_cast<int>(r.integer("kld_min_particles", p.kld_min_particles, 1, 100000));
  return p;
}

McLLocalizer::McLLocalizer(const Field& field, const McLParams& p, std::uint64_t seed, const std::string& cache_dir)
    : p_(p), field_(field), map_(field, p.cell, cache_dir), rng_(seed) {}

void McLLocalizer::reset(const std::optional<Pose2>& start) {
  ps_.clear();
  converged_ = false;
  initialised_ = false;
  w_slow_ = w_fast_ = 0.0;
  if (start) {
    for (int i = 0; i < p_.particles; ++i)
      ps_.push_back({Pose2(start->x + rng_.normal(0, 0.05), start->y + rng_.normal(0, 0.05), start->theta + rng_.normal(0, 0.02)), 0.0});
    initialised_ = true;
  }
}

void McLLocalizer::init_uniform(std::optional<double> heading) {
  // Uniform over the field (inside the lines plus half a metre), headings from the compass.
  const double hx = 0.5 * field_.length + 0.5, hy = 0.5 * field_.width + 0.5;
  ps_.clear();
  for (int i = 0; i < p_.particles; ++i) {
    const double th = heading ? *heading + rng_.normal(0, p_.heading_sigma) : rng_.uniform(-kPi, kPi);
    ps_.push_back({Pose2(rng_.uniform(-hx, hx), rng_.uniform(-hy, hy), th), 0.0});
  }
  initialised_ = true;
}

std::vector<McLLocalizer::Particle> McLLocalizer::kld_resample(const std::vector<double>& w, double sum) {
  // Fox 2003: draw one particle at a time (with replacement, by weight) and count the histogram bins
  // they fall in; stop once n >= (k - 1) / (2 eps) * (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z)^3.
  std::vector<double> cum(w.size());
  double acc = 0;
  for (std::size_t i = 0; i < w.size(); ++i) cum[i] = (acc += w[i]);
  std::vector<Particle> next;
  std::unordered_set<std::uint64_t> bins;
  const int max_n = p_.particles;
  for (int m = 0; m < max_n; ++m) {
    const double u = rng_.uniform(0, sum);
    const std::size_t i = std::min(w.size() - 1, static_cast<std::size_t>(std::lower_bound(cum.begin(), cum.end(), u) - cum.begin()));
    const Pose2& q = ps_[i].pose;
    next.push_back({q, 0.0});
    const auto bx = static_cast<std::int64_t>(std::floor(q.x / p_.kld_bin_xy)), by = static_cast<std::int64_t>(std::floor(q.y / p_.kld_bin_xy));
    const auto bt = static_cast<std::int64_t>(std::floor(wrap_angle(q.theta) / p_.kld_bin_theta));
    bins.insert((static_cast<std::uint64_t>(bx & 0xFFFFF) << 40) | (static_cast<std::uint64_t>(by & 0xFFFFF) << 20) | static_cast<std::uint64_t>(bt & 0xFFFFF));
    const double k = static_cast<double>(bins.size());
    if (k > 1 && static_cast<int>(next.size()) >= p_.kld_min_particles) {
      const double a = 2.0 / (9.0 * (k - 1));
      const double bound = (k - 1) / (2 * p_.kld_epsilon) * std::pow(1 - a + std::sqrt(a) * p_.kld_z, 3);
      if (static_cast<double>(next.size()) >= bound) break;
    }
  }
  return next;
}

Estimate McLLocalizer::update(const Observations& obs, const Odometry& odo, std::optional<double> heading) {
  if (!initialised_) init_uniform(heading);
  // Motion model: each particle follows the odometry with noise proportional to the motion.
  const double dist = std::hypot(odo.delta.x, odo.delta.y);
  const double sxy = p_.odo_trans_frac * dist + p_.odo_floor_xy;
  const double sth = p_.odo_rot_frac * std::fabs(odo.delta.theta) + p_.odo_floor_theta;
  for (auto& q : ps_)
    q.pose = q.pose.compose(Pose2(odo.delta.x + rng_.normal(0, sxy), odo.delta.y + rng_.normal(0, sxy), odo.delta.theta + rng_.normal(0, sth)));

  const auto pts = subsample(obs.line_points, p_.max_points);
  const bool see = obs.camera_ok && static_cast<int>(pts.size()) >= p_.min_points;
  if (see || heading) {
    // Log-domain weights: no underflow however many points.
    const double inv2s2 = 1.0 / (2 * p_.sigma * p_.sigma), inv2h2 = 1.0 / (2 * p_.heading_sigma * p_.heading_sigma);
    double maxlw = -1e300;
    double mean_lik = 0;
    for (auto& q : ps_) {
      double lw = 0;
      if (see) {
        const double c = std::cos(q.pose.theta), s = std::sin(q.pose.theta);
        for (const auto& o : pts) {
          const double d = std::min(p_.clamp, map_.distance({q.pose.x + c * o.x() - s * o.y(), q.pose.y + s * o.x() + c * o.y()}));
          lw -= d * d * inv2s2;
        }
        if (p_.evidence_points > 0) lw *= p_.evidence_points / static_cast<double>(pts.size());
      }
      if (heading) lw -= std::pow(angle_diff(q.pose.theta, *heading), 2) * inv2h2;
      q.logw = lw;
      maxlw = std::max(maxlw, lw);
    }
    std::vector<double> w(ps_.size());
    double sum = 0;
    for (std::size_t i = 0; i < ps_.size(); ++i) {
      w[i] = std::exp(ps_[i].logw - maxlw);
      sum += w[i];
      mean_lik += std::exp(ps_[i].logw) / ps_.size();
    }
    // Augmented MCL: inject random particles when the average likelihood drops (off by default).
    double inject = 0.0;
    if (p_.alpha_slow > 0 && p_.alpha_fast > 0) {
      w_slow_ += p_.alpha_slow * (mean_lik - w_slow_);
      w_fast_ += p_.alpha_fast * (mean_lik - w_fast_);
      inject = w_slow_ > 0 ? std::max(0.0, 1.0 - w_fast_ / w_slow_) : 0.0;
    }
    if (p_.kld) {
      ps_ = kld_resample(w, sum);
    } else {
    // Low-variance resampling.
    std::vector<Particle> next;
    next.reserve(ps_.size());
    const double step = sum / ps_.size();
    double u = rng_.uniform(0, step), acc = w[0];
    std::size_t i = 0;
    const double hx = 0.5 * field_.length + 0.5, hy = 0.5 * field_.width + 0.5;
    for (std::size_t m = 0; m < ps_.size(); ++m) {
      if (inject > 0 && rng_.uniform() < inject) {
        const double th = heading ? *heading + rng_.normal(0, p_.heading_sigma) : rng_.uniform(-kPi, kPi);
        next.push_back({Pose2(rng_.uniform(-hx, hx), rng_.uniform(-hy, hy), th), 0.0});
        continue;
      }
      const double target = u + m * step;
      while (acc < target && i + 1 < ps_.size()) acc += w[++i];
      next.push_back({ps_[i].pose, 0.0});
    }
    ps_ = std::move(next);
    }
  }
  // Estimate: mean position and circular mean heading; spread decides convergence.
  double mx = 0, my = 0, sc = 0, ss = 0;
  for (const auto& q : ps_) {
    mx += q.pose.x;
    my += q.pose.y;
    sc += std::cos(q.pose.theta);
    ss += std::sin(q.pose.theta);
  }
  const double n = static_cast<double>(ps_.size());
  mx /= n;
  my /= n;
  double vx = 0, vy = 0;
  for (const auto& q : ps_) {
    vx += (q.pose.x - mx) * (q.pose.x - mx);
    vy += (q.pose.y - my) * (q.pose.y - my);
  }
  const double spread = std::sqrt((vx + vy) / n);
  const double R = std::hypot(sc, ss) / n;
  const double theta_std = std::sqrt(std::max(0.0, -2.0 * std::log(std::max(R, 1e-12))));
  converged_ = spread < p_.converged_std && theta_std < p_.converged_theta_std;
  Estimate e;
  e.pose = Pose2(mx, my, std::atan2(ss, sc));
  e.covariance = Eigen::Vector3d(vx / n, vy / n, theta_std * theta_std).asDiagonal();
  e.valid = converged_;
  e.mode = converged_ ? LocalizerMode::kConverged : LocalizerMode::kGlobal;
  e.match_error = see ? match_error(map_, pts, e.pose, 0.25) : 1.0;
  e.extra["particles"] = n;
  e.extra["spread_m"] = spread;
  return e;
}

}  // namespace omniloc
