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
// The frame's points also share one error that does not average out over them (the camera's
// per-frame vibration tilts the whole floor picture; docs/camera.md, docs/error_budget.md): their
// information I is combined with a frame-common pose error of covariance C as a pose measurement
// of covariance I^-1 + C, written without inverting I (which is singular when one line is seen):
// W = (Id + I C)^-1 I, and the gradient b becomes (Id + I C)^-1 b.
#include <array>

#include <Eigen/Core>

#include "core/pose2.hpp"

namespace omniloc::modern {

/// What a frame's measurements contribute at one linearisation point: information
/// sum_i H_i^T R_i^-1 H_i and gradient sum_i H_i^T R_i^-1 (z_i - h_i) (rows x, y, theta).
struct InformationSum {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  Eigen::Vector3d grad = Eigen::Vector3d::Zero();
  int used = 0;  ///< measurements accumulated
};

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
  void add(const std::array<double, 6>& h, const Predicted& pred, double z, double r, InformationSum& sum) const;
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

class UkfPose {
 public:
  void reset(const Pose2& mean, const Eigen::Matrix3d& cov);
  /// x <- x (+) delta through the sigma points (the heading's spread swings the increment), then
  /// + Q (world frame).
  void predict(const Pose2& delta, const Eigen::Matrix3d& q);
  /// The iterated sensor update. `linearise(centre, sigma, sum)` adds the frame's measurements
  /// linearised at `centre` (sigma points around it with the prior covariance). `common`: the
  /// frame-common error's covariance (zero: independent measurements). Returns the last sum.
  template <class Linearise>
  InformationSum update(Linearise&& linearise, int iterations, const Eigen::Matrix3d& common);
  const Eigen::Vector3d& mean() const { return x_; }
  Pose2 pose() const { return Pose2(x_.x(), x_.y(), x_.z()); }
  const Eigen::Matrix3d& covariance() const { return p_; }
  /// One Gauss-Newton step from `at` with the prior (x_, p_) and the measurements' `sum` taken at
  /// `at`; sets `cov_out` to the posterior covariance. Public for tests.
  Eigen::Vector3d step(const Eigen::Vector3d& at, const InformationSum& sum, const Eigen::Matrix3d& common, Eigen::Matrix3d* cov_out) const;

 private:
  Eigen::Vector3d x_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d p_ = Eigen::Matrix3d::Identity();
};

template <class Linearise>
InformationSum UkfPose::update(Linearise&& linearise, int iterations, const Eigen::Matrix3d& common) {
  Eigen::Vector3d at = x_;
  Eigen::Matrix3d post = p_;
  InformationSum sum;
  int done = 0;
  for (int it = 0; it < iterations; ++it) {
    const SigmaPoints sp(at, p_);
    InformationSum next;
    linearise(at, sp, next);
    if (next.used == 0) break;  // nothing associated from here: keep the last step's result
    sum = next;
    at = step(at, sum, common, &post);
    ++done;
  }
  if (done == 0) return sum;
  x_ = at;
  x_.z() = wrap_angle(x_.z());
  p_ = 0.5 * (post + post.transpose());
  return sum;
}

}  // namespace omniloc::modern
