#include "localization/landmarks/fix.hpp"

#include <utility>

namespace omniloc::landmarks {

Fix no_fix(std::string reason) {
  Fix f;
  f.ok = false;
  f.pose = Pose2();
  f.reliability = 0.0;
  f.reason = std::move(reason);
  return f;
}

}  // namespace omniloc::landmarks
