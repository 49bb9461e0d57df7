#include "harness/perception.hpp"

namespace omniloc::harness {

std::unique_ptr<Perception> make_perception(const Scenario& s, bool needs_vision) {
  (void)s;
  if (!needs_vision) return std::make_unique<NoPerception>();
  throw RuntimeFailure("this build has no camera pipeline yet; use a localizer that needs no vision");
}

}  // namespace omniloc::harness
