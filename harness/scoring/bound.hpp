#pragma once
// The accuracy limit beside every score: a Cramér–Rao lower bound on each frame's pose (x, y,
// theta) from what that frame gave the localizer, and the posterior bound (Tichavský, Muravchik and
// Nehorai 1998) that carries information from frame to frame through the odometry model.
//
// Scoring only: the bound is computed from the true pose, the field's markings and the run's own
// residuals at the truth, so, like the truth, it never reaches a localizer.
//
// The measurement model, as the errors are made (docs/results.md "The limit"):
// - each line point, mapped to the world at the true pose, is a measurement of the signed distance
//   to its nearest marking (segment or arc) along that marking's normal; points farther than
//   kGateSigmas band sigmas from every marking are false detections (excluded, counted);
// - white noise per range band, measured from the run's residuals at the truth (1.4826 x MAD);
// - camera vibration and body tilt move all of a frame's points together: a per-frame tilt of the
//   mirror (two angles) shifts a floor point at range r by about (r^2 + h^2) / h times the tilt.
//   It is a nuisance in each frame's measurement covariance, R = D + A Sigma_c A^T, its size
//   measured from the per-frame fitted tilt's spread (the declared vibration beside it);
// - camera latency is a bias, not noise: the geometry is evaluated at the pose the image was
//   exposed at (the truth interpolated latency seconds before the frame), and the shift between
//   the two poses is reported beside the bound, never folded into a sigma;
// - a compass adds 1 / sigma^2 to the heading information (its declared white noise);
// - errors carried from frame to frame (the same lines at nearly the same pixels): a share of each
//   frame's whitened error carried on with a per-frame coefficient, both fitted to the run's own
//   autocorrelation at the truth (TemporalCorrelation below); the posterior bound holds them as
//   three more states, and the recursion with independent frames is kept beside for comparison.
// Assumptions: known association, the measured noise is Gaussian and is the truth, unbiased
// estimators. A real localizer may legitimately differ: it does not know the association (the bound
// is then optimistic), a biased estimator (a prior, a robust cost that shrinks) can go below it, and
// the run's noise estimate has sampling error. Blobs (coloured goals, landmarks) are not in the
// bound: a localizer that uses their bearings is not bounded by it.
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "harness/run_record.hpp"

namespace omniloc::harness {

/// The range bands (metres from the robot) the point noise is measured in: [0, 1.5), [1.5, 3), ...
inline constexpr std::array<double, 5> kBoundBands = {0.0, 1.5, 3.0, 5.0, 7.5};
/// A point farther than this many of its band's sigmas from every marking is a false detection.
inline constexpr double kGateSigmas = 4.0;

/// One scalar measurement of a frame: d(residual)/d(x, y, theta), its white variance and
/// d(residual)/d(tilt) (the per-frame common component: roll, pitch of the mirror, radians).
struct BoundRow {
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  double var = 1.0;
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  double e = 0.0;  ///< the residual at the true pose (only for the score below)
  int line = -1;     ///< which of the frame's markings the point lies on (0, 1, ...; -1: none shared)
  double load = 0.0; ///< its loading on that marking's shared offset (the point's sigma)
};

/// Fisher information of (x, y, theta) from rows whose errors are white (var) plus a shared tilt
/// with covariance `tilt_cov` and an offset per marking (R = D + A C A^T with A the n x (2 + lines)
/// loadings, inverted by the Woodbury identity: O(n) in the points).
/// `score`, when given, gets H^T R^-1 e: information^-1 times it is the step of the efficient
/// (generalized least squares) estimator from the true pose, the bound's own check on real data.
/// `line_corr`: the correlation of two points' errors on one marking in one frame (each marking
/// adds an offset of variance line_corr x load_i x load_j shared by its points; `var` is then the
/// rest, (1 - line_corr) sigma^2).
Eigen::Matrix3d frame_information(const std::vector<BoundRow>& rows, const Eigen::Matrix2d& tilt_cov, double line_corr = 0.0,
                                  Eigen::Vector3d* score = nullptr);

/// The covariance bound of a Fisher information matrix, or the reason there is none:
/// "points on one line" (the information has a null direction), "ill-conditioned".
struct CovarianceBound {
  bool finite = false;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  std::string why;  ///< when not finite
};
CovarianceBound invert_information(const Eigen::Matrix3d& info);

/// One step of the posterior bound in covariance form: P+ = (I + P- J_z)^-1 P-, P- = F P F^T + Q.
/// Exactly the information recursion J+ = (Q + F J^-1 F^T)^-1 + J_z where both are defined, and
/// also when P or J_z is singular (a known start pose, a frame without points).
Eigen::MatrixXd posterior_step(const Eigen::MatrixXd& P, const Eigen::MatrixXd& F, const Eigen::MatrixXd& Q, const Eigen::MatrixXd& Jz);

/// One frame of the posterior bound's own check: the motion model from the previous frame (F, Q;
/// `reset`: a kidnap, the prior drawn anew as `reset_cov`), the frame's information J and score
/// (H^T R^-1 e at the truth, e the measured minus the true residuals: -J^-1 score is the efficient
/// single-frame estimator's error) and the recorded odometry's error over the step, in the state's
/// coordinates (`process_error`: what F's noise was in this run).
struct OracleStep {
  Eigen::MatrixXd F, Q, reset_cov;
  Eigen::MatrixXd info;
  Eigen::VectorXd score, process_error;
  bool reset = false;
};
/// The check's sums over the frames whose position variance is at most `settle_pos_var` (m^2):
/// squared errors of the filter and its own variances, position and heading (states 0, 1 and 2).
struct OracleResult {
  double pos_sq = 0, heading_sq = 0, pos_var = 0, heading_var = 0;
  std::size_t frames = 0;
};
/// The filter the posterior bound describes, run in error form from error `e0` and covariance `P0`:
/// e- = F e + process_error, then e+ = (I + P- J)^-1 (e- - P- score), P+ as posterior_step. Its
/// errors match its covariance when the frames' measurement errors are independent and as modelled;
/// errors correlated from frame to frame (the same line at the same pixels for seconds, a
/// calibration error) make it miss its covariance, and the posterior bound is then optimistic by
/// about the ratio.
OracleResult posterior_oracle(const std::vector<OracleStep>& steps, const Eigen::VectorXd& e0, const Eigen::MatrixXd& P0, double settle_pos_var);

/// Errors that carry over from frame to frame (the same lines at nearly the same pixels while the robot
/// moves a little; a calibration error): the frames' measurements are not independent, and a
/// recursion that takes them so is optimistic (posterior_oracle shows by how much). The model, in
/// each frame's whitened error eta_k = J_k^{1/2} eps_k (eps_k the efficient single-frame estimator's
/// error, so eta_k has unit covariance on the range of J_k):
///   eta_k = sqrt(rho) Pi_k z_k + sqrt(1 - rho) n_k,  z_k = a z_{k-1} + sqrt(1 - a^2) w_k,
/// n, w white with unit covariance and Pi_k the projector on J_k's range: a share rho of every
/// frame's error variance is carried with coefficient a per frame, the rest is fresh. Each frame
/// keeps its own marginal covariance J_k^-1; only its correlation with the other frames is added.
struct TemporalCorrelation {
  double rho = 0.0;  ///< share of a frame's error variance that carries over (0: independent frames)
  double a = 0.0;    ///< per-frame coefficient of the carried part
  int lags = 0;      ///< the autocorrelation was fitted over lags 1..lags (frames)
  std::size_t pairs = 0;  ///< frame pairs one frame apart that entered the measurement
  std::vector<double> autocorrelation;  ///< measured, lags 1..lags (null where no pair)
  std::string why;   ///< why rho is 0 when it was not measured
};
/// The largest share taken: the fresh part's covariance (1 - rho) must stay invertible.
inline constexpr double kMaxCarriedShare = 0.9;

/// A frame's whitened error: -J^{-1/2} score (on J's range), i.e. J^{1/2} times the efficient
/// single-frame estimator's error -J^-1 score.
Eigen::Vector3d whitened_error(const Eigen::Matrix3d& info, const Eigen::Vector3d& score);

/// rho a^l fitted by least squares to the measured autocorrelation of the whitened errors at lags
/// 1..max_lag: r(l) = mean(eta_k . eta_{k+l}) / mean(|eta_k|^2) over the pairs of frames that both
/// have an error (`has`) and lie in one `segment` (between two kidnaps). a is searched on a grid of
/// 0.001, rho is its least-squares share, clamped to [0, kMaxCarriedShare]. Fewer than
/// 3 max_lag pairs one frame apart: rho 0, with why.
TemporalCorrelation fit_temporal_correlation(const std::vector<Eigen::Vector3d>& eta, const std::vector<bool>& has,
                                             const std::vector<int>& segment, int max_lag);

/// One frame's information on the state (pose, ..., z) of `states` entries whose first three are
/// the pose and last three the carried error z: H^T H / (1 - rho), H = [J^{1/2}, 0, sqrt(rho) Pi].
/// Its pose block marginalised over z (prior identity) is J again.
Eigen::MatrixXd correlated_frame_information(const Eigen::Matrix3d& info, double rho, int states);

/// posterior_oracle with the carried errors in the filter (the optimal filter of the temporal model):
/// the state is the steps' (pose first) and z behind it, z predicted by a with (1 - a^2) noise, kept
/// through a reset. `eta` per step is the frame's whitened error (whitened_error of its info and
/// score). `white`, when given, gets the independent filter's (posterior_oracle's) errors tallied
/// against this filter's covariance: a ratio below 1 beyond sampling error would be a filter
/// beating the temporal bound.
OracleResult posterior_oracle_correlated(const std::vector<OracleStep>& steps, const std::vector<Eigen::Vector3d>& eta,
                                         const TemporalCorrelation& tc, const Eigen::VectorXd& e0, const Eigen::MatrixXd& P0,
                                         double settle_pos_var, OracleResult* white = nullptr);

/// A point mapped to the world and matched to its nearest marking: the signed distance along the
/// marking's normal and that normal (world frame). `kind`: 0 none, 1 segment/arc, 2 spot.
struct MarkingMatch {
  double residual = 0.0;
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();
  int kind = 0;
  int marking = -1;  ///< index among segments then arcs (spots: -1)
};
MarkingMatch match_marking(const Field& field, const Eigen::Vector2d& w);

/// Points farther than this (metres) from every marking match none (kind 0): false detections
/// whatever the noise (4 sigma of the widest band measured on the tracking path is 0.8 m).
inline constexpr double kMatchReach = 1.0;
/// match_marking for many points at once, as the bound matches them: through a grid of the markings
/// that can be the nearest in each cell of the floor, so each point is compared with one or two
/// markings instead of all. The same match to the last bit for every point within kMatchReach of a
/// marking; kind 0 beyond.
std::vector<MarkingMatch> match_markings(const Field& field, const std::vector<Eigen::Vector2d>& world);

/// The measurement row of a robot-frame point `robot` seen from `pose`, mapped to `world` and matched
/// as `m`: d(signed distance)/d(x, y, theta) = (n_x, n_y, (w - t) x n), its tilt loading and residual.
BoundRow bound_row(const MarkingMatch& m, const Eigen::Vector2d& world, const Pose2& pose, const Eigen::Vector2d& robot, double var, double h);

/// What the scenario declares (the bound's "declared" figures and the odometry model's noise).
struct BoundSetup {
  const Field* field = nullptr;
  double mount_height = 0.75;      ///< mirror viewpoint above the floor, metres
  double latency_s = 0.0;          ///< the image shows the world this long before the frame
  double physics_dt = 0.005;       ///< the simulation's step (the exposure time lies on it)
  double camera_rate = 30.0;
  double vibration_std = 0.0;      ///< declared per-frame roll / pitch std, radians
  double tilt_per_accel = 0.0;     ///< declared body tilt per m/s^2 (not modelled as noise: said beside)
  double trans_sigma = 0.0, rot_sigma = 0.0, rot_per_trans = 0.0, scale_sigma = 0.0;  ///< odometry (sim/sensors.hpp)
  bool has_heading_sensor = false;
  double heading_sigma = 0.0;      ///< declared white noise of the compass, radians
  bool start_pose_given = false;   ///< the localizer was reset with the true start pose
  /// Frames carry odometry (simulated robots and recordings of them always do): the efficiency is
  /// then against the posterior bound, else against the single-frame one.
  bool has_odometry = true;
  std::vector<double> resets;      ///< times this robot was kidnapped: the posterior starts again
  /// With kidnaps or covers, the intervals (seconds) scoring leaves out of the tracking phase
  /// (summary.json tracking_phase.excluded): the efficiency is also given without them.
  std::vector<std::pair<double, double>> excluded;
};

/// The bound of one frame; empty where none is finite.
struct FrameBound {
  std::optional<double> pos, heading;    ///< single frame: sqrt(P_xx + P_yy), sqrt(P_thth)
  std::optional<double> ppos, pheading;  ///< posterior
};

struct RobotBound {
  std::vector<FrameBound> frames;     ///< one per FrameRecord
  Json bound;                         ///< summary.json "bound"
  Json efficiency, efficiency_single; ///< summary.json "efficiency", "efficiency_single_frame"
};

/// The bound of every frame of a robot with ground truth, its summary and the efficiency of its
/// estimates (rmse / bound RMS over the frames that have both).
RobotBound bound_robot(const RobotRecord& robot, const BoundSetup& setup);

/// What of a robot's bound the localizer's estimates do not change: the bound of every frame and
/// summary.json's "bound". It reads only what the frames gave the localizer (truth, line points,
/// camera_ok, odometry, compass, times) and the setup less `excluded`: the part the bound cache
/// (harness/bound_cache.hpp) keeps, the costly one.
struct BoundPart {
  std::vector<FrameBound> frames;
  Json bound;
};
BoundPart bound_part(const RobotRecord& robot, const BoundSetup& setup);
/// The rest: the efficiency of the robot's estimates against `part` (bound_robot is the two in turn).
RobotBound bound_from_part(const RobotRecord& robot, const BoundSetup& setup, BoundPart part);

/// rmse / bound RMS over the frames with a valid estimate and a finite bound (`against` names the
/// bound); null with why_null where there are none or the bound is 0. `exposure`: the poses the
/// images were exposed at (with camera latency), for rmse_at_exposure_m beside.
Json efficiency_json(const RobotRecord& robot, const std::vector<std::optional<double>>& pos_bound,
                     const std::vector<std::optional<double>>& heading_bound, const std::string& against,
                     const std::vector<Pose2>* exposure = nullptr, const std::vector<std::pair<double, double>>* excluded = nullptr);

}  // namespace omniloc::harness
