#include "localization/modern/ukf_pose.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "core/angles.hpp"

namespace omniloc::modern {

namespace {
constexpr double kSqrt3 = 1.7320508075688772;

// Cholesky factor of a covariance that round-off or a flat direction may have left barely
// positive: a tiny diagonal load first (1e-12 m^2 is far below anything a pose filter holds).
Eigen::Matrix3d cholesky(const Eigen::Matrix3d& cov) {
  Eigen::LLT<Eigen::Matrix3d> llt(cov + 1e-12 * Eigen::Matrix3d::Identity());
  if (llt.info() == Eigen::Success) return llt.matrixL();
  // Not positive definite: the diagonal's square roots (keeps the filter going, loses correlation).
  return cov.diagonal().cwiseMax(1e-12).cwiseSqrt().asDiagonal();
}
}  // namespace

SigmaPoints::SigmaPoints(const Eigen::Vector3d& centre, const Eigen::Matrix3d& cov) {
  const Eigen::Matrix3d l = cholesky(cov);
  for (int j = 0; j < 3; ++j) {
    pts_[static_cast<std::size_t>(j)] = centre + kSqrt3 * l.col(j);
    pts_[static_cast<std::size_t>(j + 3)] = centre - kSqrt3 * l.col(j);
  }
  l_inv_ = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
}

Eigen::RowVector3d SigmaPoints::regression(const std::array<double, 6>& h) const {
  // Pxz = sum_s W_s (X_s - x)(h_s - hbar) = (sqrt(3) / 6) sum_j L_j (h_+j - h_-j), and
  // H = Pxz^T P^-1 = Pxz^T L^-T L^-1 = [(h_+j - h_-j) / (2 sqrt(3))]_j^T L^-1.
  const Eigen::RowVector3d d((h[0] - h[3]) / (2 * kSqrt3), (h[1] - h[4]) / (2 * kSqrt3), (h[2] - h[5]) / (2 * kSqrt3));
  return d * l_inv_;
}

SigmaPoints::Predicted SigmaPoints::predict(const std::array<double, 6>& h) const {
  double mean = 0.0;
  for (double v : h) mean += v;
  mean /= 6.0;
  double pzz = 0.0;
  for (double v : h) pzz += (v - mean) * (v - mean);
  return {mean, pzz / 6.0};
}

void SigmaPoints::add(const std::array<double, 6>& h, const Predicted& pred, double z, double r, InformationSum& sum,
                      const Eigen::Vector2d* tilt, int group, double load) const {
  const Eigen::RowVector3d hr = regression(h);
  // H P H^T = sum_j d_j^2 (the regression explains exactly the antisymmetric part of h); what is
  // left of Pzz is the measurement's curvature over the spread: the regression error, added to r.
  const double d0 = (h[0] - h[3]) / (2 * kSqrt3), d1 = (h[1] - h[4]) / (2 * kSqrt3), d2 = (h[2] - h[5]) / (2 * kSqrt3);
  const double explained = d0 * d0 + d1 * d1 + d2 * d2;
  const double w = 1.0 / (r + std::max(0.0, pred.var - explained));
  sum.info.noalias() += hr.transpose() * (w * hr);
  sum.grad.noalias() += hr.transpose() * (w * (z - pred.mean));
  if (tilt) {
    sum.info_tilt.noalias() += hr.transpose() * (w * tilt->transpose());
    sum.tilt_info.noalias() += *tilt * (w * tilt->transpose());
    sum.tilt_grad.noalias() += *tilt * (w * (z - pred.mean));
  }
  if (group >= 0 && load > 0) {
    if (InformationSum::Group* g = sum.group(group)) {
      const double wl = w * load;
      g->h.noalias() += hr.transpose() * wl;
      if (tilt) g->a.noalias() += *tilt * wl;
      g->ll += wl * load;
      g->le += wl * (z - pred.mean);
    }
  }
  ++sum.used;
}

void InformationSum::marginalise(const Eigen::Matrix2d& tilt_cov, double group_var, Eigen::Matrix3d& j, Eigen::Vector3d& g) const {
  j = info;
  g = grad;
  Eigen::Matrix<double, 3, 2> ht = info_tilt;
  Eigen::Matrix2d tt = tilt_info;
  Eigen::Vector2d tg = tilt_grad;
  if (group_var > 0) {
    // Per marking, (D + rho l l^T)^-1 = D^-1 - k D^-1 l l^T D^-1 with k = rho / (1 + rho l^T D^-1 l):
    // every sum loses its share along that marking's offset.
    for (int i = 0; i < n_groups; ++i) {
      const Group& q = groups[static_cast<std::size_t>(i)];
      const double k = group_var / (1.0 + group_var * q.ll);
      j.noalias() -= k * q.h * q.h.transpose();
      g.noalias() -= (k * q.le) * q.h;
      ht.noalias() -= k * q.h * q.a.transpose();
      tt.noalias() -= k * q.a * q.a.transpose();
      tg.noalias() -= (k * q.le) * q.a;
    }
  }
  if (!tilt_cov.isZero(0.0)) {
    // S = (T^-1 + A^T R'^-1 A)^-1 = T (Id + A^T R'^-1 A T)^-1: defined for a singular T as well.
    const Eigen::Matrix2d s = tilt_cov * (Eigen::Matrix2d::Identity() + tt * tilt_cov).inverse();
    j.noalias() -= ht * s * ht.transpose();
    g.noalias() -= ht * (s * tg);
  }
  if (group_var > 0 || !tilt_cov.isZero(0.0)) j = 0.5 * (j + j.transpose()).eval();
}

Eigen::Matrix3d motion_covariance(const Pose2& delta, double theta, const MotionNoise& n) {
  const double dist = std::hypot(delta.x, delta.y), turn = std::fabs(delta.theta);
  const double var_xy = n.trans_per_sqrt_m * n.trans_per_sqrt_m * dist + (n.scale * dist) * (n.scale * dist) + n.floor_xy * n.floor_xy;
  const double var_th = n.rot_per_sqrt_rad * n.rot_per_sqrt_rad * turn + n.rot_per_sqrt_m * n.rot_per_sqrt_m * dist + n.floor_theta * n.floor_theta;
  (void)theta;  // isotropic in x and y: the robot axes' rotation into the world leaves it unchanged
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  q(0, 0) = q(1, 1) = var_xy;
  q(2, 2) = var_th;
  return q;
}

void UkfPose::reset(const Pose2& mean, const Eigen::Matrix3d& cov) {
  x_ = Eigen::Vector3d(mean.x, mean.y, mean.theta);
  p_ = cov;
  has_bias_ = false;
  b_ = pbb_ = 0.0;
  pxb_.setZero();
}

void UkfPose::start_bias(double var) {
  has_bias_ = true;
  b_ = 0.0;
  pbb_ = var;
  pxb_.setZero();
}

void UkfPose::condition_bias(const Eigen::Vector3d& x0, const Eigen::Matrix3d& p0) {
  // b = b0 + G (x - x0) + e with G = P_bx P0^-1 and e independent of x: the new x moves b's mean
  // by G dx, and its covariance: P_bb - G P0 G^T + G P G^T, P_xb = P G^T.
  const Eigen::RowVector3d g = p0.ldlt().solve(pxb_).transpose();
  const Eigen::Vector3d dx(x_.x() - x0.x(), x_.y() - x0.y(), angle_diff(x_.z(), x0.z()));
  b_ += g.dot(dx);
  pbb_ += g * (p_ - p0) * g.transpose();
  pbb_ = std::max(pbb_, 0.0);
  pxb_ = p_ * g.transpose();
}

double UkfPose::fuse_heading(double z, double var) {
  const double nu = angle_diff(z, x_.z() + (has_bias_ ? b_ : 0.0));
  // H = [0 0 1 | 1]: P H^T is the theta column plus the bias column.
  Eigen::Vector4d ph;
  ph.head<3>() = p_.col(2) + (has_bias_ ? pxb_ : Eigen::Vector3d::Zero());
  ph(3) = has_bias_ ? pxb_(2) + pbb_ : 0.0;
  const double s = ph(2) + ph(3) + var;
  if (!(s > 0)) return nu;
  const Eigen::Vector4d k = ph / s;
  x_ += k.head<3>() * nu;
  x_.z() = wrap_angle(x_.z());
  p_ -= k.head<3>() * ph.head<3>().transpose();
  p_ = 0.5 * (p_ + p_.transpose()).eval();
  if (has_bias_) {
    b_ += k(3) * nu;
    pxb_ -= k.head<3>() * ph(3);
    pbb_ = std::max(pbb_ - k(3) * ph(3), 0.0);
  }
  return nu;
}

void UkfPose::predict(const Pose2& d, const Eigen::Matrix3d& q, double bias_q) {
  // Unscented transform of f(x) = x (+) d. The centre point (weight 0 in the mean) anchors the
  // heading: the others' headings are averaged as differences from it, never across the wrap.
  const SigmaPoints sp(x_, p_);
  std::array<Eigen::Vector3d, 6> y;
  const Pose2 c = Pose2(x_.x(), x_.y(), x_.z()).compose(d);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int s = 0; s < 6; ++s) {
    const Eigen::Vector3d& v = sp[s];
    const double cs = std::cos(v.z()), sn = std::sin(v.z());
    y[static_cast<std::size_t>(s)] = Eigen::Vector3d(v.x() + cs * d.x - sn * d.y, v.y() + sn * d.x + cs * d.y, c.theta + angle_diff(v.z() + d.theta, c.theta));
    mean += y[static_cast<std::size_t>(s)] / 6.0;
  }
  Eigen::Matrix3d p = Eigen::Matrix3d::Zero();
  for (const auto& v : y) p.noalias() += (v - mean) * (v - mean).transpose() / 6.0;
  if (has_bias_) {
    // The new pose's covariance with the bias through x: Cov(f(x), x) P^-1 P_xb, Cov(f(x), x) from
    // the sigma points (the motion noise is independent of the bias).
    Eigen::Matrix3d cyx = Eigen::Matrix3d::Zero();
    for (int s = 0; s < 6; ++s) cyx.noalias() += (y[static_cast<std::size_t>(s)] - mean) * (sp[s] - x_).transpose() / 6.0;
    pxb_ = cyx * p_.ldlt().solve(pxb_);
    pbb_ += bias_q;
  }
  x_ = mean;
  x_.z() = wrap_angle(x_.z());
  p_ = p + q;
  p_ = 0.5 * (p_ + p_.transpose()).eval();
}

Eigen::Vector3d UkfPose::step(const Eigen::Vector3d& at, const InformationSum& sum, const Eigen::Matrix3d& common, Eigen::Matrix3d* cov_out,
                              const Eigen::Matrix2d& tilt_cov, double group_var) const {
  const Eigen::Matrix3d id = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d info;
  Eigen::Vector3d grad;
  sum.marginalise(tilt_cov, group_var, info, grad);
  // (Id + J C)^-1: a frame-common pose error caps what any number of points can tell.
  const Eigen::Matrix3d shrink = (id + info * common).inverse();
  const Eigen::Matrix3d w = shrink * info;
  const Eigen::Vector3d g = shrink * grad;
  const Eigen::Matrix3d p_inv = p_.inverse();
  Eigen::Matrix3d post_inv = p_inv + 0.5 * (w + w.transpose());
  Eigen::Vector3d prior_pull(x_.x() - at.x(), x_.y() - at.y(), angle_diff(x_.z(), at.z()));
  const Eigen::Matrix3d post = post_inv.inverse();
  if (cov_out) *cov_out = post;
  return at + post * (p_inv * prior_pull + g);
}

}  // namespace omniloc::modern
