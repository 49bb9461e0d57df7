#include "experiments/cooperative_001_results.hpp"

#include <stdexcept>
#include <string>

namespace omniloc::experiments {

const CoopPathStats& CoopDirectResult::model(CoopNoiseModel m) const {
  for (const auto& [key, s] : by_model)
    if (key == m) return s;
  throw std::logic_error("cooperative_001: no results for noise model " + std::string(to_string(m)));
}

bool usable(const BallFix& f) { return f.status != BallFix::Status::NoObservation; }

}  // namespace omniloc::experiments
