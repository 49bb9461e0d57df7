#pragma once
// Localizer "ukf_mh": a modern reference beside the papers' localizers, designed after the
// strongest documented self-locators of today (our own code; the methods from their published
// descriptions and sources):
// - B-Human's SelfLocator and UKFPose2D (bhuman/BHumanCodeRelease: Src/Modules/Modeling/SelfLocator,
//   Src/Tools/Modeling/UKFPose2D): a small set of hypotheses, each an unscented Kalman filter over
//   (x, y, theta) (ukf_pose.hpp); odometry prediction with noise growing with distance and rotation;
//   line-point updates with association to the field's markings inside a corridor
//   (marking_association.hpp); a validity per hypothesis, filtered over frames; merging, pruning and
//   replacement of hypotheses (hypothesis_set.hpp); twin handling by compass or goal colours.
// - The Falcons' field fit (Falcons-Robocup code, packages/multiCam determinePosition; MRA-components
//   localization_vision): a per-frame simplex fit over a field table from the previous candidates
//   plus restarts (alternative_poses.hpp), which proposes poses; a proposal replaces the weakest
//   hypothesis when the evidence disagrees with the current estimate.
// It reads what every localizer reads: line points, odometry, the heading when there is one, blobs
// of goal colours where the field has them. No start pose: it localizes globally.
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "localization/field_map.hpp"
#include "localization/localizer.hpp"
#include "localization/modern/alternative_poses.hpp"
#include "localization/modern/hypothesis_set.hpp"
#include "localization/modern/marking_association.hpp"
#include "localization/modern/ukf_pose.hpp"

namespace omniloc::modern {

/// A line point's noise variance along its marking's normal `normal` (unit), its scan ray's direction
/// being `ray` (unit, the same frame): its own variance `own_var`, plus `grazing_var` where the ray
/// meets the marking at a grazing angle (|normal . ray| below `grazing_below`). The scan lines take a
/// point at the middle of a white run along the ray, the line's centre when the run spans the line
/// from edge to edge; a ray crossing a line of width w at incidence c runs over w / c of white, which
/// below about 1 / 3 is longer than any run the detector accepts (three widths and 2 px), so an
/// accepted grazing run is a piece of the line cut by the pixels' classification, and its middle lies
/// anywhere across the line's width: w^2 / 12 more.
double incidence_variance(double own_var, const Eigen::Vector2d& ray, const Eigen::Vector2d& normal, double grazing_below, double grazing_var);

/// What the scenario's camera declares, which a localizer may know when built, as it knows the
/// field (harness::LocalizerContext): zeros where nothing declares it.
struct DeclaredCamera {
  double latency = 0.0;       ///< s: the image is this much older than the odometry
  double mount_height = 0.0;  ///< m: the mirror's viewpoint above the floor; 0 unknown
  double vibration = 0.0;     ///< rad: per-frame tilt (roll, pitch) standard deviation, each axis
};

/// Every default argued in docs/localizers.md ("ukf_mh: defaults and their arguments").
struct UkfMhParams {
  // Measurements.
  int max_points = 100;          ///< line points evenly subsampled beyond this (cost; the common error dominates beyond)
  int min_points = 10;           ///< fewer: no sensor update (matching's default; NuBot > 15, CAMBADA > 5)
  double point_sigma = 0.015;    ///< m: a line point's own noise at range weight_ref (the accuracy bound's white noise, measured)
  double weight_d = 2.5;         ///< m: point noise grows as (weight_d^2 + r^2) (NuBot's range weights)
  double weight_ref = 1.5;       ///< m: the range at which the noise is point_sigma (NuBot)
  double grazing_below = 0.3;    ///< |n.u| (marking normal, scan ray) below which the ray meets the marking at a grazing angle
  double grazing_spread = 0.28867513459481287;  ///< a grazing point's added spread across its marking, in line widths (uniform: 1 / sqrt(12)); 0: none
  double marking_sd = 0.004;     ///< m: an offset shared by a frame's points on one marking (the bound's line correlation x its white noise); 0: none
  double tilt_sd = 0.0;          ///< rad: the frame's camera tilt, each axis (JSON default: the camera's declared vibration)
  double mount_height = 0.0;     ///< m: mirror viewpoint height of the tilt's geometry (JSON default: the camera's declared one)
  double common_sd_xy = 0.03;    ///< m: where the tilt is not modelled, a frame-common error of the points' pose
  double common_sd_theta = 0.01; ///< rad
  double corridor = 0.5;         ///< m: points farther from their marking are not associated
  double gate_sigmas = 3.0;      ///< innovation gate in standard deviations
  double white_gate_sigmas = 4.0;  ///< second gate: a point's residual with the frame's own tilt taken out, in white spreads; 0: none
  double white_sigma = 0.015;    ///< m: a point's own spread once the frame's tilt is taken out (the accuracy bound's white noise)
  double inlier_sigmas = 3.0;    ///< a point fits when within this many standard deviations of its marking
  int iterations = 2;            ///< iterated update: association and linearisation again at the new mean
  double latency = 0.0;          ///< s: the image is this much older than the odometry (JSON default: the camera's declared latency)
  // Odometry.
  MotionNoise motion;
  // Hypotheses.
  HypothesisSetParams set;
  double validity_time = 0.5;    ///< s: time constant of the validity's low-pass filter
  double valid_min = 0.75;       ///< validity at which a hypothesis is reported valid
  double hysteresis = 0.05;      ///< another hypothesis must be this much more valid to take the lead
  int trust_frames = 5;          ///< frames whose mean evidence may make a hypothesis valid at once
  double trust_share = 0.9;      ///< ... when at least this: validity is raised to valid_min
  double compass_gate = 0.5;     ///< rad: a hypothesis this far from the compass heading fits nothing
  double compass_sigma = 0.017453292519943295;  ///< rad: the compass's white noise (1 deg); 0: the compass only gates
  double compass_bias_walk = 0.0017453292519943296;  ///< rad/sqrt(s): its bias's random walk (0.1 deg/sqrt(s))
  double compass_bias_sd = 0.05; ///< rad: a new hypothesis's prior on the compass bias
  double new_sd_xy = 0.1;        ///< m: a proposal's initial standard deviation
  double new_sd_theta = 0.05;    ///< rad
  // Alternative poses.
  AlternativePoseParams alt;
  int alt_points = 40;           ///< line points of the fit (evenly subsampled)
  double alt_period = 0.5;       ///< s: while tracking, a search round this often
  int alt_tracking_restarts = 20;  ///< fresh restarts per round while tracking (searching: alt.screened)
  double alt_margin = 0.05;      ///< a proposal must beat the best hypothesis's score by this to enter
  double cell = 0.05;            ///< m: distance-map cell of the fit (Tribots: 50 mm)

  /// `camera`: what the camera declares (LocalizerContext), the defaults of `latency`, `tilt_sd`
  /// and `mount_height`.
  static UkfMhParams from_json(JsonReader& r, const DeclaredCamera& camera = {});
  /// Whether the tilt is modelled with its geometry (a tilt and a height known).
  bool tilt_modelled() const { return tilt_sd > 0 && mount_height > 0; }
  /// The frame-common pose error's variance in x and y: the stand-in for the tilt where it is not
  /// modelled; where it is, the tilt is that error (it would be counted twice).
  double common_xy_var() const { return tilt_modelled() ? 0.0 : common_sd_xy * common_sd_xy; }
  static const ParamList<UkfMhParams>& params();
  static Json schema();
};

class UkfMhLocalizer : public Localizer {
 public:
  UkfMhLocalizer(const Field& field, const UkfMhParams& p, std::uint64_t seed, const std::string& cache_dir);
  std::string type() const override { return "ukf_mh"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  DebugView debug_view(std::size_t max_particles) const override;
  const std::vector<Hypothesis>& hypotheses() const { return set_; }

 private:
  /// The motion from the image's exposure to now (latency: the image shows the robot as it was):
  /// the inverse of it moves the points into the robot frame of now.
  Pose2 exposure_to_now(double t) const;
  /// Sets frame_ (the points in the robot frame of now) and tilt_ (each point's move per radian of
  /// tilt, in that frame) from the image's points.
  void prepare_points(const std::vector<Eigen::Vector2d>& image, double t);
  /// Variance of point i's distance to the marking with gradient g (world) from the tilt, at a heading
  /// of cosine c and sine s; `a` (optional): the distance's change per radian of tilt.
  double tilt_variance(std::size_t i, const Eigen::Vector2d& g, double c, double s, Eigen::Vector2d* a) const;
  void sensor_update(Hypothesis& h, const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading, const Observations& obs, double dt);
  /// A point's own noise variance (m^2) at o (robot frame, m): point_sigma at range weight_ref,
  /// grown with the range as NuBot's weights say.
  double point_variance(const Eigen::Vector2d& o) const;
  /// Point i's variance (its own, `own`, plus the grazing term) against a marking of normal g (world)
  /// at a heading of cosine c and sine s.
  double noise_variance(std::size_t i, double own, const Eigen::Vector2d& g, double c, double s) const;
  /// The share of this frame's points (frame_, whose tilt_ and ray_ rows go with them) within
  /// inlier_sigmas standard deviations of their marking at q.
  double inlier_share(const Eigen::Vector3d& q) const;
  bool contradicted(const Eigen::Vector3d& q, std::optional<double> heading, const Observations& obs) const;
  void search(const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading, bool twins_equal, bool searching);

  UkfMhParams p_;
  Field field_;
  FieldMap map_;
  MarkingAssociation assoc_;
  AlternativePoses alt_;
  std::vector<Hypothesis> set_;
  std::uint32_t next_id_ = 0;
  std::int64_t best_id_ = -1;
  bool was_valid_ = false;
  std::optional<double> last_t_;
  double last_search_t_ = -1e300;
  int proposals_ = 0;
  struct Motion {
    double t0, t1;
    Pose2 delta;
  };
  std::deque<Motion> history_;
  std::vector<Eigen::Vector2d> frame_;  // this frame's points, robot frame of now
  std::vector<Eigen::Matrix2d> tilt_;   // per point of frame_: its move per radian of tilt (empty: no tilt model)
  std::vector<Eigen::Vector2d> ray_;    // per point of frame_: its scan ray's direction (unit, robot frame of now; empty: no grazing class)
  double grazing_var_ = 0.0;            // m^2: a grazing point's added variance (grazing_spread of the field's line width)
};

}  // namespace omniloc::modern
