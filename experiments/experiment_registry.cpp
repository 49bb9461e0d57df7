#include "experiments/experiment.hpp"
#include "experiments/cooperative_001.hpp"
#include "experiments/entropy_maps.hpp"
#include "experiments/error_budget.hpp"
#include "experiments/global_figures.hpp"
#include "experiments/landmark_maps.hpp"

// Add an experiment: include its header and append one line to the list below.

namespace omniloc::experiments {

const std::vector<ExperimentInfo>& all() {
  static const std::vector<ExperimentInfo> list = {
      {"entropy_maps", "paper 002 figures 6, 10, 11: image entropy over (exposure, gain) under normal light and sun, the auto-adjust search path, frames before / after", run_entropy_maps},
      {"global_figures", "paper 000 figures 7 and 9 (grid-sample errors, RPROP traces) and an MCL particle-cloud sequence", run_global_figures},
      {"cooperative_001",
       "paper 001 simulation: Hough-space ball fix by 5 robots over a lossy network (equal vs 1/L weights, error vs robot count), "
       "FBPF vs MFBPF growth model, trackers on the fixes (scenarios/experiments/cooperative_001.json)",
       run_cooperative_001, validate_cooperative_001},
      {"error_budget",
       "which error source dominates: the tracking path with every error source off, each alone, and all together (robot, field_robot), for matching, "
       "MCL and the hybrid (scenarios/experiments/error_budget.json)",
       run_error_budget, validate_error_budget},
      {"landmark_maps", "paper 004 solver error maps and table 1, paper 003 landmark groups with voting (simulation)", run_landmark_maps},
  };
  return list;
}

}  // namespace omniloc::experiments
