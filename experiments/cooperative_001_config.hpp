#pragma once
// Configuration of the experiment "cooperative_001" (paper 001's simulation), shared by its two
// observation modes: direct noise (cooperative_001.hpp) and rendered images
// (cooperative_001_rendered.hpp). Read from an editable description file, by default
// scenarios/experiments/cooperative_001.json, strictly (every key checked, errors name the JSON
// path). Also the set-up both modes share: the per-trial random streams and the ball trackers run on
// the fixes.
//
// Coordinates: the paper's frame, metres, origin at a field corner, x along the long (6 m) side. The
// rendered mode's field uses the project's field frame (origin at the field centre), i.e. paper
// point p is field point p - (length / 2, width / 2).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/cooperative/hough_ball.hpp"
#include "sim/network.hpp"
#include "sim/render/camera_config.hpp"

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

/// Where each robot's own pose (the start of its line L_i) comes from in the rendered mode.
enum class CoopPoseSource {
  /// Self-localisation: the "matching" localizer on the robot's own rendered images for
  /// `selfloc_frames` frames, started from the true pose perturbed by start_offset / start_heading_offset.
  Matching,
  /// Ground truth + N(0, pose_sigma^2 I) on the position (fallback when self-localisation is not wanted).
  NoisyTruth,
};

const char* to_string(CoopPoseSource s);

/// "rendered" object of scenarios/experiments/cooperative_001.json.
struct CoopRenderedConfig {
  Field field;                    ///< the rendered field, field frame; same length / width as /field
  sim::CameraConfig camera;       ///< every robot's camera (default: the project's default camera)
  std::vector<double> headings;   ///< rad, world heading of each robot; empty: each faces the path's middle
  int trials = 30;                ///< Monte Carlo runs of the whole path with new image noise
  int quick_trials = 1;
  int min_area_px = 6;            ///< smallest orange region accepted as the ball (pixels)
  double ball_radius = 0.11;      ///< m, the ball every robot knows (MSL size-5 ball, sim default)
  double robot_radius = 0.26;     ///< m, the robots' footprint (sim default), also for the occlusion count
  double robot_height = 0.8;      ///< m
  CoopPoseSource pose_source = CoopPoseSource::Matching;
  Json localizer = Json{{"type", "matching"}};  ///< localizer description (localizer_registry) for Matching
  int selfloc_frames = 15;        ///< frames each robot self-localises on before the ball rolls
  double start_offset = 0.3;      ///< m, distance of the localizer's start from the true position
  double start_heading_offset = 0.17453292519943295;  ///< rad (10 degrees), start heading error
  double pose_sigma = 0.05;       ///< m, NoisyTruth only
  /// Tracker runs on the rendered fixes are cheap (no rendering): every trial feeds its fix sequence
  /// to each tracker this many times with different filter seeds.
  int tracking_repeats = 20;
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

// --- set-up shared by both modes ------------------------------------------------------------------------

/// Trial t of the random stream `name` under the run's seed (independent of every other name and
/// trial): every draw of the experiment, in both observation modes, comes from one of these.
Rng cooperative_trial_rng(std::uint64_t seed, const std::string& name, int t);

/// Hough fix settings with the given weighting (equal, or K_i = 1/L_i).
HoughBallConfig coop_hough_config(BallWeighting weighting);

/// The ball trackers run on the fixes, in table order.
const std::vector<std::string>& coop_trackers();

/// Ball tracker `name` ("kf", "pf", "fbpf", "mfbpf") with the experiment's motion model and particle
/// settings, for fixes of about `obs_sigma` metres error, started at rest at `first` (world, metres)
/// with a prior of obs_sigma in position and 2 m/s in velocity (the ball may roll at a few m/s).
std::unique_ptr<BallTracker> make_coop_tracker(const Cooperative001Config& c, const std::string& name, double obs_sigma,
                                               const Eigen::Vector2d& first);

/// A fix (or none) per path step.
using CoopFixSequence = std::vector<std::optional<Eigen::Vector2d>>;
/// The first fix of a sequence, if any.
std::optional<Eigen::Vector2d> first_fix(const CoopFixSequence& z);
/// Tracker `name` (make_coop_tracker) fed with `z`, one step per path position: its position error
/// against the true ball at every step (m).
std::vector<double> coop_tracker_errors(const Cooperative001Config& c, const std::string& name, double obs_sigma, const Eigen::Vector2d& first,
                                        const CoopFixSequence& z, Rng& rng);

}  // namespace omniloc::experiments
