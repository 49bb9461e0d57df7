#pragma once
// Ball trackers fed by the cooperative Hough fix (paper 001, section 5: Xu, Xie, Wang, Ni,
// J. Image and Graphics 2012).
//
// State X = (p_x, p_y, v_x, v_y): world frame, metres and metres per second. Constant-velocity model
// X_t = A X_{t-1} + B W_t (paper 001 section 5.2) with W_t a 2-D white Gaussian acceleration
// (m/s^2) and
//     A = [1 0 dT 0; 0 1 0 dT; 0 0 1 0; 0 0 0 1],
//     B = [dT^2/2 0; 0 dT^2/2; dT 0; 0 dT]   (rows in the state order p_x, p_y, v_x, v_y).
// The paper prints B with rows [dT^2/2 0; dT 0; 0 dT^2/2; 0 dT], which is the same matrix for the
// state order (p_x, v_x, p_y, v_y); with the paper's own A and state order the rows must be permuted
// as above, otherwise position would receive velocity noise and vice versa.
// Observation: a position fix z = (p_x, p_y) + n, n ~ N(0, obs_sigma^2 I).
//
// Trackers (common interface BallTracker): bootstrap particle filter, FBPF, MFBPF (the resampling /
// fission code shared with the growth-model benchmark, particle_core.hpp) and a linear Kalman filter
// baseline. All randomness comes from the Rng passed to step().
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/rng.hpp"
#include "localization/cooperative/particle_core.hpp"

namespace omniloc {

/// State transition A of the constant-velocity model, dt in seconds.
Eigen::Matrix4d cv_transition(double dt);
/// Noise input B (4x2) of the constant-velocity model, dt in seconds, rows (p_x, p_y, v_x, v_y).
Eigen::Matrix<double, 4, 2> cv_noise_input(double dt);

struct CvModelConfig {
  double dt = 0.04;           ///< seconds per step (paper 001's camera: 25 fps)
  /// m/s^2, std of each component of W_t (the paper gives no value). 5 m/s^2 covers rolling
  /// friction, bounces and light touches; it is also what keeps a 100-particle filter from starving:
  /// at 1 m/s^2 the velocity of a collapsed particle set diffuses only 0.04 m/s per 40 ms step and
  /// a PF started 1.3 m/s off missed a noise-free ball by more than 5 cm after 30 steps in 87 of
  /// 100 runs (docs/cooperative.md).
  double accel_sigma = 5.0;
  double obs_sigma = 0.1;     ///< metres, std of each coordinate of the position fix
};

struct ParticleTrackerConfig {
  int particles = 100;             ///< paper 001 runs 100 particles on the robot
  double threshold = 0.5;          ///< N_th / N_s (paper 001: 0.3-0.8 for FBPF, 0.5 for MFBPF)
  double fission_sigma_pos = 0.02; ///< metres, displacement std of fission offspring (position)
  double fission_sigma_vel = 0.1;  ///< m/s, displacement std of fission offspring (velocity)
};

struct BallTrackEstimate {
  Eigen::Vector4d state = Eigen::Vector4d::Zero();            ///< (p_x, p_y, v_x, v_y): m, m, m/s, m/s, world
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();   ///< of the state, SI units squared
  bool updated = false;   ///< an observation was used in this step
  double ess = 0.0;       ///< particle filters: N_eff after the update (0 for the Kalman filter)
  bool resampled = false; ///< particle filters: systematic / overwrite resampling ran
  bool fission = false;   ///< FBPF / MFBPF: SFN pre-processing ran
  bool weights_collapsed = false;  ///< every particle had zero likelihood; weights reset to uniform
};

class BallTracker {
 public:
  virtual ~BallTracker() = default;
  virtual std::string name() const = 0;
  /// Prior N(x0, P0). Particle filters draw their particles from it on the first step() (with that
  /// step's Rng), so init() itself needs no randomness.
  virtual void init(const Eigen::Vector4d& x0, const Eigen::Matrix4d& P0) = 0;
  /// One cycle of dt seconds: predict, then update with the fix if there is one (world, metres).
  virtual BallTrackEstimate step(const std::optional<Eigen::Vector2d>& fix, Rng& rng) = 0;
};

/// Linear Kalman filter on the same constant-velocity model (Q = B sigma_a^2 B^T, R = obs_sigma^2 I).
class KalmanBallTracker : public BallTracker {
 public:
  explicit KalmanBallTracker(const CvModelConfig& model = {});
  std::string name() const override { return "kf"; }
  void init(const Eigen::Vector4d& x0, const Eigen::Matrix4d& P0) override;
  BallTrackEstimate step(const std::optional<Eigen::Vector2d>& fix, Rng& rng) override;

 private:
  CvModelConfig model_;
  Eigen::Vector4d x_ = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P_ = Eigen::Matrix4d::Identity();
};

/// Bootstrap PF, FBPF or MFBPF on the constant-velocity model (paper 001 sections 5.1-5.2).
class ParticleBallTracker : public BallTracker {
 public:
  ParticleBallTracker(ParticleFilterKind kind, const CvModelConfig& model = {}, const ParticleTrackerConfig& cfg = {});
  std::string name() const override;
  void init(const Eigen::Vector4d& x0, const Eigen::Matrix4d& P0) override;
  BallTrackEstimate step(const std::optional<Eigen::Vector2d>& fix, Rng& rng) override;
  const pfcore::ParticleSet<Eigen::Vector4d>& particles() const { return set_; }

 private:
  BallTrackEstimate estimate() const;
  ParticleFilterKind kind_;
  CvModelConfig model_;
  ParticleTrackerConfig cfg_;
  Eigen::Matrix4d A_;
  Eigen::Matrix<double, 4, 2> B_;
  Eigen::Vector4d x0_ = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P0_ = Eigen::Matrix4d::Identity();
  bool sampled_ = false;
  pfcore::ParticleSet<Eigen::Vector4d> set_;
};

/// Factory: "kf", "pf", "fbpf" or "mfbpf"; nullptr for anything else.
std::unique_ptr<BallTracker> make_ball_tracker(const std::string& name, const CvModelConfig& model = {},
                                               const ParticleTrackerConfig& cfg = {});

// --- Paper 001 section 5.3 benchmark: the univariate non-stationary growth model ---------------------
//   x_k = x_{k-1}/2 + 25 x_{k-1} / (1 + x_{k-1}^2) + 8 cos(1.2 k) + v_k,   y_k = x_k^2 / 20 + w_k,
//   v ~ N(0, 10), w ~ N(0, 1), x_0 ~ N(0, 10) (variances), 100 particles, 50 steps, N_th = 50,
//   fission variance 1. Dimensionless.
struct GrowthModelConfig {
  double process_var = 10.0;
  double obs_var = 1.0;
  double x0_var = 10.0;
  double fission_var = 1.0;
  double threshold = 0.5;  ///< N_th / N_s (N_th = 50 of 100 in the paper)
};

struct GrowthModelRun {
  std::vector<double> truth;     ///< x_1..x_steps
  std::vector<double> estimate;  ///< filter means, same indices
  double rmse = 0.0;             ///< sqrt(mean (estimate - truth)^2)
};

/// One Monte Carlo run: draws the truth and observations from `rng` first (so every filter kind sees
/// the same trajectory for the same seed), then runs the filter with further draws from `rng`.
GrowthModelRun growth_model_run(ParticleFilterKind kind, int particles, int steps, Rng& rng,
                                const GrowthModelConfig& cfg = {});
double growth_model_rmse(ParticleFilterKind kind, int particles, int steps, Rng& rng,
                         const GrowthModelConfig& cfg = {});

}  // namespace omniloc
