#pragma once
// Rendered-image mode of the paper-001 simulation (docs/cooperative.md "Rendered mode"): instead of "true ball + Gaussian noise",
// every robot renders its own panorama with the simulated omnidirectional camera
// (sim/render/panoramic_camera.hpp), finds the ball (the orange colour class) with the robot-side
// BlobDetector through the calibration map and colour table of harness/vision_setup.hpp, and turns
// the blob's bearing and distance, with its own self-localised pose, into the line L_i of the Hough
// fix (localization/cooperative/hough_ball.hpp). The five robots are obstacles in each other's
// images, so occlusions are real. docs/cooperative.md, "Rendered mode", has the results.
//
// Frames and units: the experiment's "paper frame" (metres, origin at a field corner, x along the
// long side, as in cooperative_001_config.hpp); the rendered field uses the project's field frame
// (metres, origin at the field centre), i.e. paper point p is field point p - (length / 2, width / 2).
// Robot frame: x forward, y left, metres; bearings in radians anticlockwise from forward.
//
// Configuration: CoopRenderedConfig (cooperative_001_config.hpp). Computation: this file, returning
// CoopRenderedResult. Report: cooperative_001_report.hpp.
#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "experiments/cooperative_001_config.hpp"
#include "localization/cooperative/hough_ball.hpp"
#include "localization/vision/blobs.hpp"

namespace omniloc::experiments {

/// One robot's ball measurement from one panorama, robot frame.
struct RenderedBallSighting {
  bool seen = false;             ///< an orange region of at least min_area_px was found
  bool has_distance = false;     ///< its nearest ground contact lies inside the calibrated range
  double bearing = 0.0;          ///< rad, middle of the region's angular extent
  double contact_distance = 0.0; ///< m, floor distance of the region pixel nearest the image centre
  double distance = 0.0;         ///< m, ball centre's floor distance after the radius correction
  int area_px = 0;
  int regions = 0;               ///< orange regions found (the largest is used)
  Eigen::Vector2d position() const;  ///< robot frame, metres: distance * (cos bearing, sin bearing)
};

/// Horizontal distance (m) from the mirror axis to the ball centre, given the floor distance d (m)
/// where the steepest ray that still touches the ball (the region's pixel nearest the image centre)
/// meets the floor, the camera's viewpoint height h (m) and the ball radius r (m). That ray is
/// tangent to the ball on its near side, so it meets the floor short of the ball's contact point;
/// the ball centre lies at perpendicular distance r from it: D = d + r (sqrt(h^2 + d^2) - d) / h.
double ball_centre_distance(double contact_distance, double mount_height, double ball_radius);

/// The largest orange region of `blobs` (kBallOrange, Kind::kRegion) as a sighting.
RenderedBallSighting ball_sighting_from_blobs(const std::vector<Blob>& blobs, int min_area_px, double mount_height, double ball_radius);

/// Errors of one kind of fix over every trial and step (m).
struct CoopFixAcc {
  std::vector<double> errors;     ///< every usable fix's error
  std::vector<double> per_trial;  ///< per-trial mean error
  double sum_sq = 0;              ///< for the per-axis RMS
  int steps = 0, no_fix = 0, degenerate = 0, single = 0;
  double trial_sum = 0;           ///< the current trial's running sum and count
  int trial_n = 0;
  void add(const BallFix& f, const Eigen::Vector2d& ball);
  void end_trial();
  double trial_mean() const;  ///< the current trial's mean error; NaN without a fix
  double rms_per_axis() const;
};

/// The ball sightings of every robot and frame, scored against the truth.
struct CoopSightingStats {
  static constexpr int kBins = 5;  ///< true distance 0-1, 1-2, 2-3, 3-4, >= 4 m
  int total = 0, seen = 0, usable = 0, no_distance = 0, multiple_regions = 0, outliers = 0;
  int missed_fully_occluded = 0, missed_partly_occluded = 0, missed_clear = 0;
  int partly_occluded_total = 0, partly_occluded_used = 0;
  std::vector<int> missed_per_robot;
  std::vector<double> d_err, d_abs, c_err, b_abs;  ///< per usable sighting: distance (corrected, signed / abs), uncorrected signed, bearing abs
  std::vector<double> part_d_abs, part_b_abs;      ///< the same for sightings with the ball partly behind a robot
  std::array<std::vector<double>, kBins> bin_d_abs, bin_d_err, bin_b_abs;
  std::array<int, kBins> bin_missed{}, bin_total{};
  double missed_fraction() const;
};

/// Everything the rendered mode measures.
struct CoopRenderedResult {
  static constexpr double kSelflocFail = 0.1;  ///< m: a robot ending its self-localisation further off counts as a failure
  int trials = 0, path_positions = 0;
  // Wall-clock figures (the only numbers that differ between two runs with the same seed).
  double render_ms = 0;  ///< summed over the frames
  int renders = 0;
  double setup_s = 0, elapsed_s = 0;
  // Self-localisation, per robot and trial.
  std::vector<double> pos_err, head_err, start_pos_err;
  std::vector<std::vector<double>> pos_err_robot;
  std::vector<std::string> failures;  ///< "trial t robot i: e mm, h deg"
  int trials_ok = 0;                  ///< trials without a failure
  CoopSightingStats sightings;
  std::vector<double> own_err;        ///< each usable sighting turned into a ball position, against the truth
  // Fixes: all robots with their estimated poses, with the true poses (diagnostic), and over the trials without a failure.
  CoopFixAcc f_eq, f_w, f_eq_true, f_w_true, f_eq_ok, f_w_ok;
  std::vector<double> diff_per_trial, diff_ok;  ///< per trial: 1/L mean - equal mean (all trials; without a failure)
  // Robot-count curve, index = subset size: every subset, trial and step.
  std::vector<double> sub_eq_sum, sub_w_sum, sub_n, sub_nofix, sub_steps;
  std::vector<std::vector<double>> sub_w_err;
  // Trackers on the fix sequences.
  std::vector<CoopFixSequence> seq_w, seq_eq;  ///< [trial][step]
  std::vector<std::string> tracking_inputs;    ///< "1/L fix", "equal fix"
  std::vector<double> tracking_obs_sigma;      ///< per input (its per-axis RMS)
  std::vector<std::vector<double>> track_mean; ///< [input][tracker], m (NaN without runs)
};

/// The rendered mode (c.rendered must be set) with `trials` path runs. `progress`: optional one-line
/// status stream (one line per trial).
CoopRenderedResult compute_cooperative_rendered(const Cooperative001Config& c, int trials, std::uint64_t seed, std::ostream* progress = nullptr);

}  // namespace omniloc::experiments
