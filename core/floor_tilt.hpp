#pragma once
// The geometry of a camera tilt seen on the floor, shared by the accuracy bound
// (harness/scoring/bound.cpp) and the localizer that models it (localization/modern/ukf_pose.cpp).
#include <Eigen/Core>

namespace omniloc {

/// How a floor point p (robot frame, metres) seen from a mirror viewpoint h metres above the floor
/// moves per radian of camera tilt; columns: the tilt about the robot's x axis (roll) and y axis
/// (pitch). The point is seen along the ray (p, -h); turning the camera by small angles w turns the
/// ray by w x ray, which meets the floor h (-wy, wx) sideways plus p (wx py - wy px) / h along the
/// range: (r^2 + h^2) / h per radian towards the point, h across it.
inline Eigen::Matrix2d floor_tilt_jacobian(const Eigen::Vector2d& p, double h) {
  Eigen::Matrix2d m;
  m << p.x() * p.y() / h, -h - p.x() * p.x() / h,  //
      h + p.y() * p.y() / h, -p.x() * p.y() / h;
  return m;
}

}  // namespace omniloc
