#pragma once
#include "experiments/experiment.hpp"

namespace omniloc::experiments {

/// "entropy_maps": image entropy over (exposure, gain) for normal light and strong sun (paper 002
/// figures 6 and 11c) with the auto-adjust search path drawn on it, the entropy along the search line
/// exposure = gain, and the frames before and after adjustment (figures 10 and 11), from the start
/// pose of scenarios/paper/lighting_002*.json.
int run_entropy_maps(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
