#include "harness/experiment.hpp"
#include "harness/experiments/global_figures.hpp"
#include "harness/experiments/landmark_maps.hpp"

// Add an experiment: include its header and append one line to the list below.

namespace omniloc::harness {

const std::vector<ExperimentInfo>& experiments() {
  static const std::vector<ExperimentInfo> list = {
      {"global_figures", "paper 000 figures 7 and 9 (grid-sample errors, RPROP traces) and an MCL particle-cloud sequence", run_global_figures},
      {"landmark_maps", "paper 004 solver error maps and table 1, paper 003 landmark groups with voting (simulation)", run_landmark_maps},
  };
  return list;
}

}  // namespace omniloc::harness
