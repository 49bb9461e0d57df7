#include "localization/mcl.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "localization/filter/particle_set.hpp"
#include "localization/matching.hpp"

namespace omniloc {

const ParamList<McLParams>& McLParams::params() {
  using P = McLParams;
  static const ParamList<P> list = {
      integer_param("particles", &P::particles, 10, 100000, "particles (paper 002: 600); with kld the maximum"),
      positive_param("sigma", &P::sigma, 5.0, "m", "sensor model std of a point's distance to the nearest line"),
      positive_param("clamp", &P::clamp, 10.0, "m", "distances beyond count as this (points on robots, noise)"),
      integer_param("max_points", &P::max_points, 1, 10000, "line points evenly subsampled per frame, for speed"),
      integer_param("min_points", &P::min_points, 1, 10000, "fewer line points: no sensor update"),
      number_param("evidence_points", &P::evidence_points, 0.0, 10000.0, "", "the log-likelihood sum is scaled to this many points' worth (0: the paper's plain product)"),
      positive_param("heading_sigma", &P::heading_sigma, 10.0, "rad", "compass term in the weight and spread of the initial headings"),
      positive_param("converged_std", &P::converged_std, 10.0, "m", "position spread below this = converged"),
      positive_param("converged_theta_std", &P::converged_theta_std, 10.0, "rad", "heading spread below this = converged"),
      number_param("alpha_slow", &P::alpha_slow, 0.0, 1.0, "", "augmented MCL: slow average of the likelihood (0 = off)"),
      number_param("alpha_fast", &P::alpha_fast, 0.0, 1.0, "", "augmented MCL: fast average of the likelihood (0 = off)"),
      number_param("cell", &P::cell, 0.005, 0.5, "m", "distance-map cell"),
      bool_param("adapt_to_no_compass", &P::adapt_to_no_compass,
                 "without a compass at the first frame: no_compass_particles as a KLD-adaptive set and no_compass_clamp (false: paper 002's set whatever the sensors)"),
      integer_param("no_compass_particles", &P::no_compass_particles, 10, 100000, "without a compass: the first set (then KLD-adaptive)"),
      positive_param("no_compass_clamp", &P::no_compass_clamp, 10.0, "m", "without a compass: the sensor model's clamp"),
  };
  return list;
}

Json McLParams::schema() {
  const McLParams d;
  Json s = params_schema(params(), d);
  s.update(params_schema(filter::OdometryNoiseParams::params(filter::OdometryNoiseParams::Keys::Planar), d.odometry));
  s.update(params_schema(filter::KldParams::params(), d.kld));
  return s;
}

McLParams McLParams::from_json(JsonReader& r) {
  McLParams p;
  read_params(r, p, params());
  p.odometry = filter::OdometryNoiseParams::from_json(r, p.odometry, filter::OdometryNoiseParams::Keys::Planar);
  p.kld = filter::KldParams::from_json(r);
  return p;
}

McLLocalizer::McLLocalizer(const Field& field, const McLParams& p, std::uint64_t seed, const std::string& cache_dir)
    : p_(p), field_(field), map_(field, p.cell, cache_dir), rng_(seed) {}

void McLLocalizer::reset(const std::optional<Pose2>& start) {
  ps_.clear();
  converged_ = false;
  initialised_ = false;
  w_slow_ = w_fast_ = 0.0;
  resets_ = 0;
  if (start) {
    // A known start: a tight cloud around it (5 cm, 0.02 rad).
    for (int i = 0; i < p_.particles; ++i) ps_.push_back({filter::perturb(*start, {0.05, 0.02}, rng_), 0.0});
    initialised_ = true;
  }
}

Pose2 McLLocalizer::random_pose(std::optional<double> heading) {
  // Inside the lines plus half a metre (a robot on the line sees the field too). Draw order heading,
  // y, x: the order of the expression this replaced (see filter::perturb), so runs reproduce.
  const double hx = 0.5 * field_.length + 0.5, hy = 0.5 * field_.width + 0.5;
  const double th = heading ? *heading + rng_.normal(0, p_.heading_sigma) : rng_.uniform(-kPi, kPi);
  const double y = rng_.uniform(-hy, hy);
  const double x = rng_.uniform(-hx, hx);
  return Pose2(x, y, th);
}

void McLLocalizer::init_uniform(std::optional<double> heading) {
  if (!heading && !initialised_ && p_.adapt_to_no_compass && !no_compass_) {
    // A global start without a compass: see McLParams::adapt_to_no_compass.
    no_compass_ = true;
    p_.particles = p_.no_compass_particles;
    p_.clamp = p_.no_compass_clamp;
    p_.kld.enabled = true;
  }
  ps_.clear();
  for (int i = 0; i < p_.particles; ++i) ps_.push_back({random_pose(heading), 0.0});
  initialised_ = true;
}

void McLLocalizer::predict(const Pose2& delta) {
  // Each particle follows the odometry with its own noise, proportional to the motion.
  const filter::OdometrySigmas s = filter::odometry_sigmas(delta, p_.odometry);
  for (auto& q : ps_) q.pose = q.pose.compose(filter::perturb(delta, s, rng_));
}

double McLLocalizer::log_likelihood(const Pose2& q, const std::vector<Eigen::Vector2d>* pts, std::optional<double> heading) const {
  // Log domain: a sum over points, no underflow however many there are.
  double lw = 0;
  if (pts) {
    const double inv2s2 = 1.0 / (2 * p_.sigma * p_.sigma);
    // In table cells: the rotation and the scaling by 1 / cell are one multiplication; the table
    // is a local so its fields stay in registers.
    const FieldMap::Table t = map_.table();
    const double a = std::cos(q.theta) * t.inv_cell, b = std::sin(q.theta) * t.inv_cell, clamp = p_.clamp;
    const double px = t.cells_x(q.x), py = t.cells_y(q.y);
    for (const auto& o : *pts) {
      const double d = std::min(clamp, t.at_cells<false>(px + a * o.x() - b * o.y(), py + b * o.x() + a * o.y()).d);
      lw -= d * d * inv2s2;
    }
    if (p_.evidence_points > 0) lw *= p_.evidence_points / static_cast<double>(pts->size());
  }
  if (heading) {
    const double inv2h2 = 1.0 / (2 * p_.heading_sigma * p_.heading_sigma);
    lw -= std::pow(angle_diff(q.theta, *heading), 2) * inv2h2;
  }
  return lw;
}

bool McLLocalizer::possible(const Pose2& q) const {
  return std::fabs(q.x) <= field_.half_floor_x() && std::fabs(q.y) <= field_.half_floor_y();
}

double McLLocalizer::weigh(const std::vector<Eigen::Vector2d>* pts, std::optional<double> heading) {
  // The map constraint (Thrun, Burgard, Fox, Probabilistic Robotics, 5.7: p(x | u, x', m) is
  // proportional to p(x | u, x') p(x | m), and p(x | m) = 0 where the robot cannot be): a particle
  // the motion model carried beyond the walls weighs nothing. Without it a set that converged on a
  // wrong pose follows the odometry through the wall, every point there is clamped alike, and
  // nothing ever tells the particles apart again (seed 2 of the tracking path from a global start
  // was tracked out to x = 15.6 m: docs/global_localization.md).
  // nav2_amcl draws its initial and injected poses from free map cells only, for the same reason.
  logw_.resize(ps_.size());
  std::size_t alive = 0;
  for (std::size_t i = 0; i < ps_.size(); ++i) {
    const bool ok = possible(ps_[i].pose);
    alive += ok;
    logw_[i] = ps_[i].logw = ok ? log_likelihood(ps_[i].pose, pts, heading) : -std::numeric_limits<double>::infinity();
  }
  if (alive == 0) {
    // Every hypothesis is impossible: the set has lost the robot. Start the global search again
    // (uniform over the floor), as at the first frame.
    ++resets_;
    init_uniform(heading);
    for (std::size_t i = 0; i < ps_.size(); ++i) logw_[i] = ps_[i].logw = log_likelihood(ps_[i].pose, pts, heading);
  }
  filter::weights_from_log(logw_, w_);
  return filter::weight_sum(w_);
}

double McLLocalizer::injection_rate() {
  if (!(p_.alpha_slow > 0 && p_.alpha_fast > 0)) return 0.0;
  // Thrun et al., Probabilistic Robotics, table 8.3: short- and long-term averages of the mean
  // likelihood; inject when the short one drops below the long one.
  double mean_lik = 0;
  for (const auto& q : ps_) mean_lik += std::exp(q.logw) / ps_.size();
  // Both averages start at the first mean likelihood, not at 0 (as nav2_amcl's pf_update_sensor
  // does): started at 0, w_slow needs about 1 / alpha_slow updates to approach the likelihood
  // (1000 frames, 33 s at 30 Hz with amcl's 0.001) while w_fast gets there 100 times sooner, so
  // w_fast / w_slow stayed far above 1 and no particle was injected for the first half minute,
  // when a wrong global convergence happens.
  if (w_slow_ == 0.0 || w_fast_ == 0.0) w_slow_ = w_fast_ = mean_lik;
  w_slow_ += p_.alpha_slow * (mean_lik - w_slow_);
  w_fast_ += p_.alpha_fast * (mean_lik - w_fast_);
  const double rate = w_slow_ > 0 ? std::max(0.0, 1.0 - w_fast_ / w_slow_) : 0.0;
  // After an injection both averages restart (nav2_amcl pf_update_resample, "to avoid spiraling off
  // into complete randomness"): the random particles lower the next mean likelihood, which would
  // otherwise lower w_fast further and inject more, frame after frame at 30 Hz.
  if (rate > 0) w_slow_ = w_fast_ = 0.0;
  return rate;
}

void McLLocalizer::resample(double sum, double inject, std::optional<double> heading) {
  std::vector<Particle> next;
  if (p_.kld.enabled) {
    // Fox 2003: as many independent draws as the bins they fill call for (no injection).
    const auto pose_of = [&](std::size_t i) -> const Pose2& { return ps_[i].pose; };
    const auto drawn = filter::kld_resample(w_, sum, p_.particles, p_.kld, pose_of, rng_);
    next.reserve(drawn.size());
    for (std::size_t i : drawn) next.push_back({ps_[i].pose, 0.0});
  } else {
    // Low-variance resampling; augmented MCL replaces some slots by random poses.
    next.reserve(ps_.size());
    filter::LowVarianceSampler sampler(w_, sum, ps_.size(), rng_);
    for (std::size_t m = 0; m < ps_.size(); ++m) {
      if (inject > 0 && rng_.uniform() < inject) next.push_back({random_pose(heading), 0.0});
      else next.push_back({ps_[sampler.index(m)].pose, 0.0});
    }
  }
  ps_ = std::move(next);
}

Estimate McLLocalizer::estimate(bool see, const std::vector<Eigen::Vector2d>& pts) {
  // Mean position and circular mean heading; their spread decides convergence.
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
  e.extra["resets"] = static_cast<double>(resets_);
  return e;
}

Estimate McLLocalizer::update(const Observations& obs, const Odometry& odo, std::optional<double> heading) {
  if (!initialised_) init_uniform(heading);
  predict(odo.delta);
  const auto pts = subsample(obs.line_points, p_.max_points);
  const bool see = obs.camera_ok && static_cast<int>(pts.size()) >= p_.min_points;
  // Without points or compass there is nothing to weigh by: the set only moves.
  if (see || heading) {
    const double sum = weigh(see ? &pts : nullptr, heading);
    resample(sum, injection_rate(), heading);
  }
  return estimate(see, pts);
}

DebugView McLLocalizer::debug_view(std::size_t max_particles) const {
  DebugView v;
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& p : ps_) top = std::max(top, p.logw);
  for (const std::size_t i : even_stride(ps_.size(), max_particles)) {
    const Particle& p = ps_[i];
    v.particles.push_back({p.pose.x, p.pose.y, p.pose.theta, std::isfinite(top) ? std::exp(p.logw - top) : 0.0});
  }
  return v;
}

}  // namespace omniloc
