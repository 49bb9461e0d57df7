#include "harness/perception.hpp"

#include "harness/camera_perception.hpp"

namespace omniloc::harness {

std::unique_ptr<Perception> make_perception(const Scenario& s, bool needs_vision, std::uint64_t seed) {
  if (!needs_vision) return std::make_unique<NoPerception>();
  return std::make_unique<CameraPerception>(s, seed);
}

}  // namespace omniloc::harness
