#include "localization/odometry_only.hpp"

namespace omniloc {

void OdometryOnlyLocalizer::reset(const std::optional<Pose2>& start) {
  started_ = start.has_value();
  pose_ = start.value_or(Pose2());
}

Estimate OdometryOnlyLocalizer::update(const Observations&, const Odometry& odometry, std::optional<double>) {
  pose_ = pose_.compose(odometry.delta);
  Estimate e;
  e.pose = pose_;
  e.valid = started_;
  e.mode = LocalizerMode::kDeadReckoning;
  e.covariance.setZero();
  return e;
}

}  // namespace omniloc
