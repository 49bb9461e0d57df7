#include "harness/experiment.hpp"
#include "harness/experiments/entropy_maps.hpp"
#include "harness/experiments/global_figures.hpp"

// Add an experiment: include its header and append one line to the list below.

namespace omniloc::harness {

const std::vector<ExperimentInfo>& experiments() {
  static const std::vector<ExperimentInfo> list = {
      {"entropy_maps", "paper 002 figures 6, 10, 11: image entropy over (exposure, gain) under normal light and sun, the auto-adjust search path, frames before / after", run_entropy_maps},
      {"global_figures", "paper 000 figures 7 and 9 (grid-sample errors, RPROP traces) and an MCL particle-cloud sequence", run_global_figures},
  };
  return list;
}

}  // namespace omniloc::harness
