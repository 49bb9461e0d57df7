#pragma once
// Monte Carlo localization (paper 002): particles uniform on the field with compass headings, an
// odometry motion model, the sensor model prod_i exp(-d(o_i)^2 / (2 sigma^2)) through the distance
// map (evaluated in the log domain), low-variance resampling, and convergence when the particle
// spread falls below a threshold. Optional augmented-MCL random injection (alpha_slow / alpha_fast,
// as in ROS amcl), off by default.
#include <vector>

#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "localization/field_map.hpp"
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
  double odo_trans_frac = 0.1, odo_rot_frac = 0.1;  ///< motion noise, fraction of the motion
  double odo_floor_xy = 0.03, odo_floor_theta = 0.02;  ///< m, rad per frame (keeps the set diverse)
  double converged_std = 0.15;    ///< m: position spread below this = converged
  double converged_theta_std = 0.1;  ///< rad
  double alpha_slow = 0.0, alpha_fast = 0.0;  ///< augmented MCL (0 = off)
  // KLD-adaptive sample size (Fox 2003; ROS amcl's pf_err / pf_z), off by default: particles are drawn
  // until their number bounds the KL distance between the sample and the true posterior by
  // kld_epsilon with probability given by kld_z (upper standard-normal quantile), histogram bins of
  // kld_bin_xy x kld_bin_xy x kld_bin_theta, between kld_min_particles and `particles`.
  bool kld = false;
  double kld_epsilon = 0.05;      ///< amcl pf_err
  double kld_z = 2.326;           ///< amcl pf_z = 0.99
  double kld_bin_xy = 0.5;        ///< m (amcl: 0.5 m)
  double kld_bin_theta = 0.1745;  ///< rad (amcl: 10 degrees)
  int kld_min_particles = 100;
  double cell = 0.05;
  static McLParams from_json(JsonReader& r);
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

 private:
  void init_uniform(std::optional<double> heading);
  std::vector<Particle> kld_resample(const std::vector<double>& w, double sum);
  McLParams p_;
  Field field_;
  FieldMap map_;
  Rng rng_;
  std::vector<Particle> ps_;
  bool initialised_ = false, converged_ = false;
  double w_slow_ = 0.0, w_fast_ = 0.0;
};

}  // namespace omniloc
