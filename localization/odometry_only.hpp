#pragma once
// Dead reckoning from the start pose: integrates odometry and ignores vision. The honest baseline
// every vision localizer must beat; its error table is the odometry drift of the scenario.
#include "localization/localizer.hpp"

namespace omniloc {

class OdometryOnlyLocalizer : public Localizer {
 public:
  std::string type() const override { return "odometry_only"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;

 private:
  Pose2 pose_;
  bool started_ = false;
};

}  // namespace omniloc
