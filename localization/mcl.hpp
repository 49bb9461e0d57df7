#pragma once
// Monte Carlo localization (paper 002): particles uniform on the field with compass headings, an
// odometry motion model (filter/odometry_noise.hpp), the sensor model
// prod_i exp(-d(o_i)^2 / (2 sigma^2)) through the distance map (evaluated in the log domain),
// low-variance resampling (filter/particle_set.hpp), and convergence when the particle spread falls
// below a threshold. Optional, off by default: augmented-MCL random injection (alpha_slow /
// alpha_fast, as in ROS amcl) and KLD-adaptive sample sizes (filter/kld.hpp).
// Units: metres and radians; particle poses and the estimate in the world frame, line points in the
// robot frame.
#include <vector>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/rng.hpp"
#include "localization/field_map.hpp"
#include "localization/filter/kld.hpp"
#include "localization/filter/odometry_noise.hpp"
#include "localization/localizer.hpp"

namespace omniloc {

struct McLParams {
  int particles = 600;            ///< paper 002
  double sigma = 0.25;            ///< m, sensor model std of a point's distance to the nearest line
  double clamp = 0.6;             ///< m, distances beyond count as this (points on robots, noise)
  int max_points = 40;            ///< evenly subsampled per frame, for speed
  int min_points = 10;
  /// The paper's product over points treats every point as independent evidence; neighbouring line
  /// points are not, and the product then collapses the particle set in one frame. The sum of
  /// log-likelihoods is scaled to this many points' worth (0: the paper's plain product).
  double evidence_points = 4.0;
  double heading_sigma = 0.15;    ///< rad: compass term in the weight and spread of initial headings
  /// Motion noise per frame (JSON odo_trans_frac 0.1, odo_rot_frac 0.1, odo_floor_xy 0.03 m,
  /// odo_floor_theta 0.02 rad; no odo_rot_per_m). The floors keep the set diverse.
  filter::OdometryNoiseParams odometry{0.1, 0.1, 0.0, 0.03, 0.02};
  double converged_std = 0.15;    ///< m: position spread below this = converged
  double converged_theta_std = 0.1;  ///< rad
  double alpha_slow = 0.0, alpha_fast = 0.0;  ///< augmented MCL (0 = off)
  /// KLD-adaptive sample size (filter/kld.hpp; JSON kld, kld_epsilon, kld_z, kld_bin_xy,
  /// kld_bin_theta, kld_min_particles), off by default; `particles` is then the maximum.
  filter::KldParams kld;
  double cell = 0.05;
  /// Without a compass (no heading at the first frame) the initial set must cover every heading,
  /// a pose space about 17 times larger than paper 002's (uniform headings over 2 pi against the
  /// compass prior's effective width sqrt(2 pi) 0.15 rad = 0.38 rad). 600 particles then put 0.06-0.11
  /// of them where the true pose beats every wrong one (measured on NuBot's real frames: a
  /// 0.16-0.29 m^2 rad region), and standing still nothing brings others there. So, when adapting:
  /// `no_compass_particles` as the first set (KLD-adaptive afterwards, so the two 180-degree twins of
  /// a symmetric field are decided in about a second instead of being held by thousands of
  /// particles), and `no_compass_clamp` as the clamp, which widens that region to 0.49-1.11 m^2 rad
  /// (paper 000's global grid search uses c = 2.55 m for the same reason). With a compass nothing
  /// changes: paper 002's configuration. data/real/nubot/README.md has the measurements.
  bool adapt_to_no_compass = true;
  int no_compass_particles = 5000;
  double no_compass_clamp = 2.0;  ///< m
  static McLParams from_json(JsonReader& r);
  /// Its own keys (plus filter::OdometryNoiseParams' planar odo_* keys and filter::KldParams').
  static const ParamList<McLParams>& params();
  static Json schema();
};

class McLLocalizer : public Localizer {
 public:
  McLLocalizer(const Field& field, const McLParams& p, std::uint64_t seed, const std::string& cache_dir);
  std::string type() const override { return "mcl"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  bool converged() const { return converged_; }
  const FieldMap& map() const { return map_; }
  struct Particle {
    Pose2 pose;        ///< world frame
    double logw = 0.0; ///< log weight (unnormalised)
  };
  /// The current particle set (for pictures and tests).
  const std::vector<Particle>& particles() const { return ps_; }
  /// An even-stride subsample of the set, weights relative to the heaviest particle.
  DebugView debug_view(std::size_t max_particles) const override;

 private:
  // One update is: predict (motion model) -> weigh (sensor model) -> resample -> estimate.
  void init_uniform(std::optional<double> heading);
  /// A pose uniform over the field plus half a metre, heading from the compass if there is one.
  Pose2 random_pose(std::optional<double> heading);
  void predict(const Pose2& delta);
  /// Log-likelihood of particle pose q: the line points' clamped distances (`pts`, robot frame;
  /// null when the camera saw too little) and the compass.
  double log_likelihood(const Pose2& q, const std::vector<Eigen::Vector2d>* pts, std::optional<double> heading) const;
  /// Inside the walls (the floor the robot can stand on): the map constraint.
  bool possible(const Pose2& q) const;
  /// Sets every particle's logw (-inf beyond the walls) and fills w_ with the relative weights;
  /// returns their sum. A set wholly beyond the walls is drawn again uniformly first.
  double weigh(const std::vector<Eigen::Vector2d>* pts, std::optional<double> heading);
  /// Augmented MCL: the fraction of random particles to inject (0 unless alpha_slow, alpha_fast set).
  double injection_rate();
  void resample(double sum, double inject, std::optional<double> heading);
  Estimate estimate(bool see, const std::vector<Eigen::Vector2d>& pts);
  McLParams p_;
  Field field_;
  FieldMap map_;
  Rng rng_;
  std::vector<Particle> ps_;
  std::vector<double> logw_, w_;  ///< per-update scratch (kept to avoid reallocation)
  bool initialised_ = false, converged_ = false;
  bool no_compass_ = false;  ///< adapted to a start without a compass (McLParams::adapt_to_no_compass)
  double w_slow_ = 0.0, w_fast_ = 0.0;
  int resets_ = 0;  ///< times the whole set was beyond the walls and drawn again
};

}  // namespace omniloc
