#include "core/pose2.hpp"

#include <cmath>

namespace omniloc {

Eigen::Matrix2d Pose2::rotation() const {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

Eigen::Vector2d Pose2::transform(const Eigen::Vector2d& local) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {x + c * local.x() - s * local.y(), y + s * local.x() + c * local.y()};
}

Eigen::Vector2d Pose2::inverse_transform(const Eigen::Vector2d& parent) const {
  const double c = std::cos(theta), s = std::sin(theta);
  const double dx = parent.x() - x, dy = parent.y() - y;
  return {c * dx + s * dy, -s * dx + c * dy};
}

Pose2 Pose2::compose(const Pose2& o) const {
  const Eigen::Vector2d t = transform({o.x, o.y});
  return {t.x(), t.y(), theta + o.theta};
}

Pose2 Pose2::inverse() const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {-(c * x + s * y), -(-s * x + c * y), -theta};
}

Pose2 Pose2::between(const Pose2& to) const {
  const Eigen::Vector2d t = inverse_transform({to.x, to.y});
  return {t.x(), t.y(), angle_diff(to.theta, theta)};
}

}  // namespace omniloc
