#pragma once
// Experiment "cooperative_001": paper 001's simulation (Xu, Xie, Wang, Ni, J. Image and Graphics
// 2012, section 6): five robots observe a ball rolling across a 6 m x 4 m field, share their
// sightings over a simulated radio network and fuse them in Hough space (localization/cooperative/).
// The set-up (robots, ball path, noise, network, trial counts) is read from an editable description
// file, by default scenarios/experiments/cooperative_001.json; docs/cooperative.md has the results.
//
// Coordinates: the paper's frame, metres, origin at a field corner, x along the 6 m side.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "experiments/experiment.hpp"
#include "experiments/cooperative_001_rendered.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "sim/network.hpp"

namespace omniloc::experiments {

/// Where each robot's observation noise enters (the paper only says "Gaussian noise, 192 mm").
enum class CoopNoiseModel {
  /// Isotropic N(0, sigma^2 I) on the ball position each robot reports (its own estimate).
  Cartesian,
  /// On what a camera measures: distance L + N(0, sigma^2) and bearing + N(0, (sigma / L_ref)^2),
  /// so the sideways error is sigma at the reference distance L_ref and grows with L.
  Polar,
  /// On the robot's own self-localised position, N(0, sigma^2 I); the relative sighting is exact.
  RobotPose,
};

const char* to_string(CoopNoiseModel m);

struct CoopTrials {
  int path = 2000;          ///< Monte Carlo runs of the whole ball path (headline numbers)
  int per_subset = 50;      ///< runs per robot subset for the error-vs-robot-count figure (paper: 50)
  int tracking = 300;       ///< runs for the tracker table
  int growth_model = 2000;  ///< Monte Carlo runs of the growth-model benchmark
};

struct Cooperative001Config {
  std::string description;
  double field_length = 6.0;  ///< m (x)
  double field_width = 4.0;   ///< m (y)
  std::vector<Eigen::Vector2d> robots;   ///< m, paper frame
  Eigen::Vector2d ball_start = Eigen::Vector2d::Zero();  ///< m
  Eigen::Vector2d ball_end = Eigen::Vector2d::Zero();    ///< m
  double ball_step = 0.05;    ///< m travelled per step
  double step_time = 0.04;    ///< s per step (25 fps camera, so 1.25 m/s for 50 mm steps)
  CoopNoiseModel noise_model = CoopNoiseModel::Polar;
  double sigma = 0.192;       ///< m
  /// m, the polar model's L_ref; absent: the mean robot-ball distance over the path and the robots.
  std::optional<double> reference_distance;
  sim::NetworkConfig network;        ///< used for every run except the lossy one (default: ideal)
  sim::NetworkConfig lossy_network;  ///< the second network run
  /// s: the fuser waits at most this long after a stamp for that stamp's sightings; later ones are dropped.
  double fusion_deadline = 0.16;  ///< lossy default: latency 0.1 s + 3 x jitter 0.02 s
  CoopTrials trials;
  CoopTrials quick_trials{60, 8, 8, 40};
  double accel_sigma = 5.0;   ///< m/s^2, trackers' process noise (ball_trackers.hpp default)
  int particles = 100;        ///< particle filters' N_s (paper: 100)
  double tracking_threshold = 0.5;  ///< N_th / N_s (paper: 0.5 for MFBPF)
  /// The rendered-image mode (key "rendered"; absent: direct-noise mode only).
  std::optional<CoopRenderedConfig> rendered;

  /// Number of ball positions on the path (start included; the end when the length is a multiple of the step).
  int path_positions() const;
  Eigen::Vector2d ball_at(double t) const;  ///< the ball at time t (s): constant velocity, not clamped
  double reference_distance_or_mean() const;
};

/// Strict parsing (every key checked; unknown keys and bad values raise ConfigError with the JSON path).
Cooperative001Config parse_cooperative_001(const Json& j);
Cooperative001Config load_cooperative_001(const std::string& file);
/// scenarios/experiments/cooperative_001.json in the source tree.
std::string cooperative_001_default_file();
void validate_cooperative_001(const std::string& file);

/// Runs the experiment (args.config or the default file), writes cooperative_001.{json,md},
/// robots_vs_error.{png,csv}, field.png (and with "rendered": robots_vs_error_rendered.{png,csv})
/// into args.out_dir and prints the tables.
/// Ball tracker `name` ("kf", "pf", "fbpf", "mfbpf") with the experiment's motion model and particle
/// settings, for fixes of about `obs_sigma` metres error, started at rest at `first` (world, metres)
/// with a prior of obs_sigma in position and 2 m/s in velocity (the ball may roll at a few m/s).
std::unique_ptr<BallTracker> make_coop_tracker(const Cooperative001Config& c, const std::string& name, double obs_sigma,
                                               const Eigen::Vector2d& first);

/// Trial t of the random stream `name` under the run's seed (independent of every other name and
/// trial): every draw of the experiment, in both observation modes, comes from one of these.
Rng cooperative_trial_rng(std::uint64_t seed, const std::string& name, int t);

int run_cooperative_001(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
