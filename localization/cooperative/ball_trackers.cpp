// Ball trackers and the growth-model benchmark of paper 001 section 5. See ball_trackers.hpp and
// particle_core.hpp.
#include "localization/cooperative/ball_trackers.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace omniloc {

const char* to_string(ParticleFilterKind k) {
  switch (k) {
    case ParticleFilterKind::Bootstrap: return "pf";
    case ParticleFilterKind::Fission: return "fbpf";
    case ParticleFilterKind::ModifiedFission: return "mfbpf";
  }
  return "unknown";
}

Eigen::Matrix4d cv_transition(double dt) {
  Eigen::Matrix4d A = Eigen::Matrix4d::Identity();
  A(0, 2) = dt;
  A(1, 3) = dt;
  return A;
}

Eigen::Matrix<double, 4, 2> cv_noise_input(double dt) {
  Eigen::Matrix<double, 4, 2> B = Eigen::Matrix<double, 4, 2>::Zero();
  B(0, 0) = 0.5 * dt * dt;
  B(1, 1) = 0.5 * dt * dt;
  B(2, 0) = dt;
  B(3, 1) = dt;
  return B;
}

namespace {

/// A square root L of a covariance (L L^T = P); negative eigenvalues are clamped to zero.
Eigen::Matrix4d covariance_root(const Eigen::Matrix4d& P) {
  const Eigen::Matrix4d sym = 0.5 * (P + P.transpose());
  Eigen::LLT<Eigen::Matrix4d> llt(sym);
  if (llt.info() == Eigen::Success) return llt.matrixL();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(sym);
  const Eigen::Vector4d s = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return eig.eigenvectors() * s.asDiagonal();
}

Eigen::Vector4d standard_normal4(Rng& rng) {
  Eigen::Vector4d v;
  for (int i = 0; i < 4; ++i) v(i) = rng.normal();
  return v;
}

}  // namespace

// --- Kalman filter -------------------------------------------------------------------------------------

KalmanBallTracker::KalmanBallTracker(const CvModelConfig& model) : model_(model) {}

void KalmanBallTracker::init(const Eigen::Vector4d& x0, const Eigen::Matrix4d& P0) {
  x_ = x0;
  P_ = P0;
}

BallTrackEstimate KalmanBallTracker::step(const std::optional<Eigen::Vector2d>& fix, Rng& /*rng*/) {
  const Eigen::Matrix4d A = cv_transition(model_.dt);
  const Eigen::Matrix<double, 4, 2> B = cv_noise_input(model_.dt);
  const double qa = model_.accel_sigma * model_.accel_sigma;
  x_ = A * x_;
  P_ = A * P_ * A.transpose() + qa * B * B.transpose();
  BallTrackEstimate e;
  if (fix && std::isfinite(fix->x()) && std::isfinite(fix->y())) {
    const Eigen::Matrix2d S = P_.topLeftCorner<2, 2>() + model_.obs_sigma * model_.obs_sigma * Eigen::Matrix2d::Identity();
    const Eigen::Matrix<double, 4, 2> K = P_.leftCols<2>() * S.inverse();
    x_ += K * (*fix - x_.head<2>());
    // Standard covariance update, symmetrised against round-off.
    P_ = P_ - K * P_.topRows<2>();
    P_ = 0.5 * (P_ + P_.transpose());
    e.updated = true;
  }
  e.state = x_;
  e.covariance = P_;
  return e;
}

// --- Particle filters ----------------------------------------------------------------------------------

ParticleBallTracker::ParticleBallTracker(ParticleFilterKind kind, const CvModelConfig& model,
                                         const ParticleTrackerConfig& cfg)
    : kind_(kind), model_(model), cfg_(cfg), A_(cv_transition(model.dt)), B_(cv_noise_input(model.dt)) {
  if (cfg_.particles < 1) cfg_.particles = 1;
}

std::string ParticleBallTracker::name() const { return to_string(kind_); }

void ParticleBallTracker::init(const Eigen::Vector4d& x0, const Eigen::Matrix4d& P0) {
  x0_ = x0;
  P0_ = P0;
  sampled_ = false;
  set_.x.assign(static_cast<std::size_t>(cfg_.particles), x0);
  set_.w.assign(static_cast<std::size_t>(cfg_.particles), 1.0 / cfg_.particles);
}

BallTrackEstimate ParticleBallTracker::estimate() const {
  BallTrackEstimate e;
  e.state = pfcore::weighted_mean(set_);
  const double s = pfcore::weight_sum(set_.w);
  Eigen::Matrix4d C = Eigen::Matrix4d::Zero();
  for (std::size_t i = 0; i < set_.size(); ++i) {
    const Eigen::Vector4d d = set_.x[i] - e.state;
    C += (s > 0.0 ? set_.w[i] / s : 1.0 / static_cast<double>(set_.size())) * d * d.transpose();
  }
  e.covariance = C;
  e.ess = pfcore::effective_sample_size(set_.w);
  return e;
}

BallTrackEstimate ParticleBallTracker::step(const std::optional<Eigen::Vector2d>& fix, Rng& rng) {
  if (!sampled_) {  // draw the prior N(x0, P0) with this step's stream
    const Eigen::Matrix4d L = covariance_root(P0_);
    for (Eigen::Vector4d& x : set_.x) x = x0_ + L * standard_normal4(rng);
    std::fill(set_.w.begin(), set_.w.end(), 1.0 / static_cast<double>(set_.size()));
    sampled_ = true;
  }
  const double sa = model_.accel_sigma;
  pfcore::predict(set_, [&](Eigen::Vector4d& x, Rng& r) {
    const double wx = sa * r.normal();
    const double wy = sa * r.normal();
    x = A_ * x + B_ * Eigen::Vector2d(wx, wy);
  }, rng);

  const bool have = fix && std::isfinite(fix->x()) && std::isfinite(fix->y());
  if (!have) return estimate();  // prediction only: weights unchanged, nothing resampled

  const double inv_var = 1.0 / (model_.obs_sigma * model_.obs_sigma);
  const Eigen::Vector2d z = *fix;
  const bool ok = pfcore::update(kind_, set_, [&](const Eigen::Vector4d& x) {
    return -0.5 * inv_var * (x.head<2>() - z).squaredNorm();
  });
  BallTrackEstimate e = estimate();  // paper 001: output before SFN / resampling
  e.updated = true;
  e.weights_collapsed = !ok;
  const double sp = cfg_.fission_sigma_pos, sv = cfg_.fission_sigma_vel;
  const pfcore::PostInfo info = pfcore::post(kind_, set_, cfg_.threshold, [&](Eigen::Vector4d& x, Rng& r) {
    x(0) += sp * r.normal();
    x(1) += sp * r.normal();
    x(2) += sv * r.normal();
    x(3) += sv * r.normal();
  }, rng);
  e.resampled = info.resampled;
  e.fission = info.fission;
  return e;
}

std::unique_ptr<BallTracker> make_ball_tracker(const std::string& name, const CvModelConfig& model,
                                               const ParticleTrackerConfig& cfg) {
  if (name == "kf") return std::make_unique<KalmanBallTracker>(model);
  if (name == "pf") return std::make_unique<ParticleBallTracker>(ParticleFilterKind::Bootstrap, model, cfg);
  if (name == "fbpf") return std::make_unique<ParticleBallTracker>(ParticleFilterKind::Fission, model, cfg);
  if (name == "mfbpf") return std::make_unique<ParticleBallTracker>(ParticleFilterKind::ModifiedFission, model, cfg);
  return nullptr;
}

// --- Growth model (paper 001 section 5.3) ----------------------------------------------------------------

namespace {
double growth(double x, int k) { return 0.5 * x + 25.0 * x / (1.0 + x * x) + 8.0 * std::cos(1.2 * k); }
}  // namespace

GrowthModelRun growth_model_run(ParticleFilterKind kind, int particles, int steps, Rng& rng,
                                const GrowthModelConfig& cfg) {
  GrowthModelRun run;
  if (particles < 1 || steps < 1) return run;
  const double sv = std::sqrt(cfg.process_var), sw = std::sqrt(cfg.obs_var), s0 = std::sqrt(cfg.x0_var);
  const double sf = std::sqrt(cfg.fission_var);

  // Truth and observations first, so the trajectory depends on the seed only.
  std::vector<double> y(static_cast<std::size_t>(steps));
  run.truth.resize(static_cast<std::size_t>(steps));
  double x = s0 * rng.normal();
  for (int k = 1; k <= steps; ++k) {
    x = growth(x, k) + sv * rng.normal();
    run.truth[static_cast<std::size_t>(k - 1)] = x;
    y[static_cast<std::size_t>(k - 1)] = x * x / 20.0 + sw * rng.normal();
  }

  pfcore::ParticleSet<double> set;
  set.x.resize(static_cast<std::size_t>(particles));
  set.w.assign(static_cast<std::size_t>(particles), 1.0 / particles);
  for (double& p : set.x) p = s0 * rng.normal();  // x_0^i ~ p(x_0)
  const double inv_var = 1.0 / cfg.obs_var;
  double se = 0.0;
  run.estimate.resize(static_cast<std::size_t>(steps));
  for (int k = 1; k <= steps; ++k) {
    pfcore::predict(set, [&](double& p, Rng& r) { p = growth(p, k) + sv * r.normal(); }, rng);
    const double yk = y[static_cast<std::size_t>(k - 1)];
    pfcore::update(kind, set, [&](double p) {
      const double r = yk - p * p / 20.0;
      return -0.5 * inv_var * r * r;
    });
    const double est = pfcore::weighted_mean(set);
    run.estimate[static_cast<std::size_t>(k - 1)] = est;
    const double d = est - run.truth[static_cast<std::size_t>(k - 1)];
    se += d * d;
    pfcore::post(kind, set, cfg.threshold, [&](double& p, Rng& r) { p += sf * r.normal(); }, rng);
  }
  run.rmse = std::sqrt(se / steps);
  return run;
}

double growth_model_rmse(ParticleFilterKind kind, int particles, int steps, Rng& rng, const GrowthModelConfig& cfg) {
  return growth_model_run(kind, particles, steps, rng, cfg).rmse;
}

}  // namespace omniloc
