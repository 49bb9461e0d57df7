#pragma once
// Matching-optimisation tracking (paper 002; Lauer, Lange, Riedmiller 2005 "Calculating the perfect
// match"): minimise sum_i e(d(o_i)) with e(t) = 1 - c^2 / (c^2 + t^2) over the pose by RPROP, take the
// uncertainty from the error's second derivatives, and fuse with odometry in a Kalman filter
// (filter/pose_kalman.hpp).
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "localization/field_map.hpp"
#include "localization/filter/odometry_noise.hpp"
#include "localization/filter/pose_kalman.hpp"
#include "localization/localizer.hpp"
#include "localization/match_data_term.hpp"

namespace omniloc {

struct MatchingParams {
  double c = 0.25;               ///< m, error scale (Tribots: c = 250 mm)
  double c_start = 0.5;          ///< m; > c: continuation, c halves from c_start down to c, each stage run to
                                 ///< convergence (smooths the error early, for starts far from the pose; the
                                 ///< default one stage at 2 c: 100 % vs 99.4 % within 5 cm from (30 cm, 30 cm,
                                 ///< 0.15 rad) cold starts, tests/localization_test.cpp). JSON default: 2 c.
  double step_xy = 0.04;         ///< m, RPROP initial step (Tribots: 40 mm)
  double step_theta = 0.1;       ///< rad, RPROP initial step (Tribots: 0.1)
  double grow = 1.2, shrink = 0.5;  ///< RPROP step factors (Tribots)
  /// RPROP stops when its steps in x, y (metres) and theta (radians) are all below this. 1 mm: the
  /// noise of the match itself is larger (200 points with 3 cm noise fix a pose to ~3 mm, the 5 cm
  /// distance map is exact to ~2.5 cm), and RPROP's step bounds its distance to the minimum.
  /// 1 mrad moves a point 3 m away (typical) by 3 mm, the same order.
  double step_tol = 0.001;
  /// Cap on RPROP iterations over all stages (Tribots ran a fixed 10, or 20 with few points; NuBot 25).
  /// Warm tracking starts stop at step_tol after ~10-15; the cap serves cold starts: from (30 cm,
  /// 30 cm, 0.15 rad) 25 leave 3.8 % of them beyond 5 cm, 40 none of 500 (median 30 iterations).
  int max_iterations = 40;
  int min_points = 10;           ///< fewer: no match, coast on odometry (NuBot needs > 15, CAMBADA > 5)
  int max_points = 200;          ///< evenly subsampled beyond this
  double heading_prior = 2.5;    ///< weight of (theta - predicted theta)^2 (Tribots: 2.5)
  double point_sigma = 0.05;     ///< m, line-point noise used to turn curvature into covariance
  double cell = 0.05;            ///< m, distance-map cell (Tribots: 50 mm)
  /// Range weights (NuBot, Whites::calculateWeights): point i at range r_i (metres from the robot)
  /// weighs w_i = (weight_ref^2 + weight_d^2) / (weight_d^2 + r_i^2), so a point at weight_ref weighs
  /// 1 and far points, whose floor positions a pixel or a tilt of the camera moves most, less.
  bool range_weights = true;
  double weight_d = 2.5;         ///< m (NuBot: 250 cm)
  double weight_ref = 1.5;       ///< m (NuBot: 150 cm)
  /// Standard deviation of the camera's tilt (roll and pitch each, radians) that moves every line
  /// point of a frame at once: a floor point at range r seen from height camera_height moves
  /// radially by (h^2 + r^2) / h per radian. Its effect on the matched pose enters the Kalman
  /// measurement covariance (it does not shrink with the number of points). 0: points independent.
  /// Default 0: 0.0052 (0.3 deg, docs/camera.md vibration) halves heading errors again on the paper
  /// path but loses on the occlusion path's p95 (docs/vision_and_tracking.md "Against NuBot's code").
  double tilt_sd = 0.0;          ///< rad
  double camera_height = 0.75;   ///< m, mirror viewpoint above the floor (docs/camera.md mount_height)
  /// Odometry process noise of the Kalman filter per frame (JSON odo_trans_frac 0.05, odo_rot_frac
  /// 0.05, odo_rot_per_m 0.02 rad/m, odo_floor_xy 0.002 m, odo_floor_theta 0.002 rad).
  filter::OdometryNoiseParams odometry{0.05, 0.05, 0.02, 0.002, 0.002};
  static MatchingParams from_json(JsonReader& r);
  /// Its own keys (the odo_* keys are filter::OdometryNoiseParams::params(Keys::WithRotPerMetre)).
  static const ParamList<MatchingParams>& params();
  /// JSON Schema properties of every key it reads.
  static Json schema();
};

struct MatchResult {
  Pose2 pose;
  double error = 0.0;  ///< mean e(d) over the points, in [0, 1)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  int iterations = 0;
  bool converged = false;  ///< the steps fell below step_tol at the final c before the cap
  int points = 0;
};

/// The range weights of `pts` (robot frame) under p (empty when p.range_weights is off).
PointWeights range_weights(const std::vector<Eigen::Vector2d>& pts, const MatchingParams& p);

/// Mean error of the points (robot frame) at `pose`.
double match_error(const FieldMap& map, const std::vector<Eigen::Vector2d>& points, const Pose2& pose, double c);

/// RPROP from `start` until its steps are all below p.step_tol (at the final c), at most
/// `max_iterations` iterations over all continuation stages.
/// `prior_theta`: optional heading the heading_prior term pulls towards.
/// `trace`: if given, receives the mean error (at the final c) before each iteration and at the end.
MatchResult rprop_match(const FieldMap& map, const std::vector<Eigen::Vector2d>& points, const Pose2& start, const MatchingParams& p,
                        int max_iterations, std::optional<double> prior_theta = std::nullopt, std::vector<double>* trace = nullptr);

/// Localizer "matching": tracking from a given start pose.
class MatchingLocalizer : public Localizer {
 public:
  MatchingLocalizer(const Field& field, const MatchingParams& p, const std::string& cache_dir);
  std::string type() const override { return "matching"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  /// Tracking step usable by other localizers (hybrid, grid_global).
  Estimate track(const Observations& obs, const Odometry& odometry);
  const FieldMap& map() const { return map_; }
  filter::PoseKalman& filter() { return kf_; }

 private:
  MatchingParams p_;
  FieldMap map_;
  filter::PoseKalman kf_;
  bool started_ = false;
};

/// Evenly subsamples to at most n points (deterministic).
std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& pts, int n);

}  // namespace omniloc
