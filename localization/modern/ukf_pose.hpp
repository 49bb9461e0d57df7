#pragma once
// An unscented Kalman filter over the planar pose (x, y in metres, theta in radians; world frame),
// after B-Human's UKFPose2D (bhuman/BHumanCodeRelease, Src/Tools/Modeling/UKFPose2D; Laue, Graf et
// al.): the motion update pushes sigma points through the composition with the odometry increment,
// the sensor update linearises each scalar measurement statistically over the sigma points.
//
// Our own formulation of the sensor update, because a frame brings up to a hundred line points and
// each is a scalar measurement: the sigma-point (statistical linear regression) form of the
// information filter (Lefebvre, Bruyninckx, De Schutter 2002; Vercauteren, Wang 2005): for each
// measurement H_i = Pxz_i^T P^-1 and the regression residual (Pzz_i - H_i P H_i^T) is added to its
// noise, and the information sum_i H_i^T R_i^-1 H_i is accumulated in 3 x 3, so a frame costs
// O(points) and never inverts an m x m matrix. On a linear measurement this is the Kalman filter's
// update exactly (tests/modern_localizer_test.cpp checks that). Iterated as Gauss-Newton around the
// updated mean with the prior kept fixed (the iterated Kalman filter; Bell, Cathey 1993), so that
// points are associated again from a better pose.
//
// The frame's points also share errors that do not average out over them. The camera's per-frame
// tilt (vibration: roll and pitch) moves each floor point by its own geometry, (r^2 + h^2) / h per
// radian along its range and h across it (docs/camera.md): a nuisance w of two unknowns with prior
// covariance T, entering point i as a_i . w. It is marginalised per frame: the points' noise is
// D + A T A^T, whose inverse by Woodbury needs only sums over the points (H^T D^-1 H, H^T D^-1 A,
// A^T D^-1 A and the gradients), so a frame still costs O(points):
//   J = H^T D^-1 H - H^T D^-1 A S A^T D^-1 H,   S = (T^-1 + A^T D^-1 A)^-1 = T (Id + A^T D^-1 A T)^-1.
// Near points hardly move with a tilt while far ones move a lot, so the points' spread in range
// separates the tilt from the pose (the same model as the accuracy bound's, harness/scoring/bound.cpp).
// Points on one marking share part of their error as well (the line's image as a whole: its edges'
// blur and classification along its length, the map's error over the ranges it spans): a further
// nuisance, one offset per marking and frame, entering point i of that marking as l_i z with z of
// prior variance rho (ukf_mh: l_i the offset's standard deviation in metres, the same for every
// point, and rho 1). The markings' offsets are independent, so R' = D + L rho L^T is block diagonal by marking
// and each block is inverted by Sherman-Morrison from four more sums per marking (H^T D^-1 l,
// A^T D^-1 l, l^T D^-1 l, l^T D^-1 (z - h)); the tilt is then marginalised against R' as above.
// Both are exact, and a frame still costs O(points).
// What else is common to a frame may be given as a pose error of covariance C, combined as a pose
// measurement of covariance J^-1 + C, written without inverting J (singular when one line is seen):
// W = (Id + J C)^-1 J, and the gradient b becomes (Id + J C)^-1 b.
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "core/floor_tilt.hpp"
#include "core/pose2.hpp"

namespace omniloc::modern {

/// What a frame's measurements contribute at one linearisation point: information
/// sum_i H_i^T R_i^-1 H_i and gradient sum_i H_i^T R_i^-1 (z_i - h_i) (rows x, y, theta).
struct InformationSum {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  Eigen::Vector3d grad = Eigen::Vector3d::Zero();
  /// The tilt nuisance's sums: H^T D^-1 A, A^T D^-1 A, A^T D^-1 (z - h).
  Eigen::Matrix<double, 3, 2> info_tilt = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix2d tilt_info = Eigen::Matrix2d::Zero();
  Eigen::Vector2d tilt_grad = Eigen::Vector2d::Zero();
  int used = 0;  ///< measurements accumulated
  /// Back to no measurements.
  void clear() {
    info.setZero();
    grad.setZero();
    info_tilt.setZero();
    tilt_info.setZero();
    tilt_grad.setZero();
    used = 0;
    n_groups = 0;
    slot_of = filled_slots();
  }
  /// One marking's sums for its shared offset (load l: the offset's effect on a point's value):
  /// H^T D^-1 l, A^T D^-1 l, l^T D^-1 l and l^T D^-1 (z - h).
  /// Set when a marking's first measurement comes (the first n_groups are in use; the rest are not
  /// initialised: a frame's sums are made twice per hypothesis, most without any group).
  struct Group {
    Eigen::Vector3d h;
    Eigen::Vector2d a;
    double ll, le;
    int id;
  };
  /// A frame sees about ten markings; the points of any beyond this many are taken as independent.
  static constexpr int kMaxGroups = 32;
  std::array<Group, kMaxGroups> groups;
  int n_groups = 0;
  /// The group of each id below kDirectIds (-1: none yet), so that a point finds its marking's sums
  /// without a search; larger ids are searched for.
  static constexpr int kDirectIds = 64;
  std::array<std::int8_t, kDirectIds> slot_of = filled_slots();
  static constexpr std::array<std::int8_t, kDirectIds> filled_slots() {
    std::array<std::int8_t, kDirectIds> a{};
    for (auto& v : a) v = -1;
    return a;
  }
  /// The sums of marking `id` (>= 0), started at zero on its first measurement; null when
  /// kMaxGroups markings already have theirs.
  Group* group(int id);
  /// The pose's information and gradient with the markings' offsets (standardized prior variance
  /// `group_var`: the correlation of two points on one marking; 0: none) and the tilt (prior
  /// covariance `tilt_cov`) marginalised.
  void marginalise(const Eigen::Matrix2d& tilt_cov, double group_var, Eigen::Matrix3d& j, Eigen::Vector3d& g) const;
  /// marginalise() without the markings' offsets.
  void marginalise_tilt(const Eigen::Matrix2d& tilt_cov, Eigen::Matrix3d& j, Eigen::Vector3d& g) const { marginalise(tilt_cov, 0.0, j, g); }
};

// Inline: it is called once per associated point, the update's innermost loop.
inline InformationSum::Group* InformationSum::group(int id) {
  const bool direct = id < kDirectIds;
  if (direct) {
    const int k = slot_of[static_cast<std::size_t>(id)];
    if (k >= 0) return &groups[static_cast<std::size_t>(k)];
  } else {
    for (int k = 0; k < n_groups; ++k)
      if (groups[static_cast<std::size_t>(k)].id == id) return &groups[static_cast<std::size_t>(k)];
  }
  if (n_groups >= kMaxGroups) return nullptr;
  if (direct) slot_of[static_cast<std::size_t>(id)] = static_cast<std::int8_t>(n_groups);
  Group& g = groups[static_cast<std::size_t>(n_groups++)];
  g.h.setZero();
  g.a.setZero();
  g.ll = g.le = 0.0;
  g.id = id;
  return &g;
}

/// The 2 n + 1 = 7 sigma points of a 3-D Gaussian and their regression helpers. Julier and
/// Uhlmann's choice n + kappa = 3 (kappa = 0) matches the fourth moment of a Gaussian; the centre
/// point then has weight 0 and the six others 1 / 6 each, at mean +- sqrt(3) L_j (L the Cholesky
/// factor of the covariance).
class SigmaPoints {
 public:
  /// Around `centre` with covariance `cov` (positive definite).
  SigmaPoints(const Eigen::Vector3d& centre, const Eigen::Matrix3d& cov);
  /// Point s (0..5): centre + sqrt(3) L_j for s = j, centre - sqrt(3) L_j for s = j + 3.
  const Eigen::Vector3d& operator[](int s) const { return pts_[static_cast<std::size_t>(s)]; }
  /// The unscented prediction of a scalar measurement from its values h[0..5] at the six points.
  struct Predicted {
    double mean = 0.0;  ///< the measurement's predicted value
    double var = 0.0;   ///< its variance over the sigma points (Pzz)
  };
  Predicted predict(const std::array<double, 6>& h) const;
  /// Adds the measurement z with noise variance r to `sum`, linearised at the centre by the
  /// regression of h (the regression error Pzz - H P H^T joins r).
  /// `tilt` (optional): d(z)/d(tilt) of the measurement, accumulated for the tilt's marginalisation.
  /// `group` (>= 0): the marking whose shared offset the measurement carries with load `load`
  /// (r is then only the measurement's own, independent part).
  void add(const std::array<double, 6>& h, const Predicted& pred, double z, double r, InformationSum& sum,
           const Eigen::Vector2d* tilt = nullptr, int group = -1, double load = 0.0) const;
  /// H (1 x 3) of the regression for values h (central differences in the sigma coordinates).
  Eigen::RowVector3d regression(const std::array<double, 6>& h) const;

 private:
  std::array<Eigen::Vector3d, 6> pts_;
  Eigen::Matrix3d l_inv_;  // L^-1
};

/// Motion noise of one odometry increment (robot frame of the previous pose), growing with the
/// distance and the angle: wheel slip is a random walk, so variances grow linearly with the
/// distance travelled (and the angle turned); a wheel-scale error grows the standard deviation
/// linearly with the distance; floors keep a standing robot's filter from becoming certain.
struct MotionNoise {
  double trans_per_sqrt_m = 0.015;  ///< m / sqrt(m), along each robot axis
  double scale = 0.01;              ///< fraction of the distance (wheel scale)
  double rot_per_sqrt_rad = 0.035;  ///< rad / sqrt(rad) turned
  double rot_per_sqrt_m = 0.01;     ///< rad / sqrt(m) travelled
  double floor_xy = 0.001;          ///< m per frame
  double floor_theta = 0.001;       ///< rad per frame
};

/// The increment's noise covariance in the world frame of a robot at heading `theta`.
Eigen::Matrix3d motion_covariance(const Pose2& delta, double theta, const MotionNoise& n);

/// The pose filter, optionally with a compass's bias b beside the pose: a compass reads theta + b +
/// white noise, and b walks at random (an MTi-class heading sensor: docs/scenario.md, the robot
/// noise profile), so its readings are not independent of one another and cannot be fused as if they
/// were. The bias enters no other measurement and no motion, so it is kept as a linear appendix to
/// the unscented pose filter: its mean, variance and cross-covariance with the pose. A pose update
/// that does not see the bias moves it by Gaussian conditioning (b given x: b + P_bx P_xx^-1 dx),
/// the motion carries the cross-covariance through the sigma points' regression, and a compass
/// reading is a linear Kalman update of the joint (x, b).
class UkfPose {
 public:
  /// Starts at `mean` with covariance `cov`; no bias state.
  void reset(const Pose2& mean, const Eigen::Matrix3d& cov);
  /// Adds the compass bias state: mean 0, variance `var`, uncorrelated with the pose.
  void start_bias(double var);
  bool has_bias() const { return has_bias_; }
  double bias() const { return b_; }
  double bias_variance() const { return pbb_; }
  const Eigen::Vector3d& bias_cross() const { return pxb_; }
  /// x <- x (+) delta through the sigma points (the heading's spread swings the increment), then
  /// + Q (world frame); the bias's variance grows by `bias_q`.
  void predict(const Pose2& delta, const Eigen::Matrix3d& q, double bias_q = 0.0);
  /// A compass reading z of theta + bias (variance `var` of its white noise; without a bias state,
  /// of theta): the Kalman update of (x, b). Returns the innovation (wrapped).
  double fuse_heading(double z, double var);
  /// The iterated sensor update. `linearise(centre, sigma, sum)` adds the frame's measurements
  /// linearised at `centre` (sigma points around it with the prior covariance). `tilt_cov`: the
  /// frame's tilt prior (zero: none); `common`: any further frame-common pose error's covariance
  /// (zero: none); `group_var`: the markings' shared offsets' standardized variance (0: none).
  template <class Linearise>
  void update(Linearise&& linearise, int iterations, const Eigen::Matrix3d& common,
                        const Eigen::Matrix2d& tilt_cov = Eigen::Matrix2d::Zero(), double group_var = 0.0);
  const Eigen::Vector3d& mean() const { return x_; }
  Pose2 pose() const { return Pose2(x_.x(), x_.y(), x_.z()); }
  const Eigen::Matrix3d& covariance() const { return p_; }
  /// One Gauss-Newton step from `at` with the prior (x_, p_) and the measurements' `sum` taken at
  /// `at`; sets `cov_out` to the posterior covariance. Public for tests.
  Eigen::Vector3d step(const Eigen::Vector3d& at, const InformationSum& sum, const Eigen::Matrix3d& common, Eigen::Matrix3d* cov_out,
                       const Eigen::Matrix2d& tilt_cov = Eigen::Matrix2d::Zero(), double group_var = 0.0) const;

 private:
  /// After the pose moved from (x0, p0) to (x_, p_) on evidence that does not see the bias.
  void condition_bias(const Eigen::Vector3d& x0, const Eigen::Matrix3d& p0);
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d p_ = Eigen::Matrix3d::Identity();
  bool has_bias_ = false;
  double b_ = 0.0, pbb_ = 0.0;
  Eigen::Vector3d pxb_ = Eigen::Vector3d::Zero();
};

template <class Linearise>
void UkfPose::update(Linearise&& linearise, int iterations, const Eigen::Matrix3d& common, const Eigen::Matrix2d& tilt_cov,
                               double group_var) {
  Eigen::Vector3d at = x_;
  Eigen::Matrix3d post = p_;
  // Two sums used in turn: the last one that had measurements is kept without copying its groups.
  InformationSum sums[2];
  int last = -1;
  for (int it = 0; it < iterations; ++it) {
    const SigmaPoints sp(at, p_);
    InformationSum& next = sums[last == 0 ? 1 : 0];
    next.clear();
    linearise(at, sp, next);
    if (next.used == 0) break;  // nothing associated from here: keep the last step's result
    last = last == 0 ? 1 : 0;
    at = step(at, next, common, &post, tilt_cov, group_var);
  }
  if (last < 0) return;
  const Eigen::Vector3d x0 = x_;
  const Eigen::Matrix3d p0 = p_;
  x_ = at;
  x_.z() = wrap_angle(x_.z());
  p_ = 0.5 * (post + post.transpose());
  if (has_bias_) condition_bias(x0, p0);
}

}  // namespace omniloc::modern
