#pragma once
#include "experiments/experiment.hpp"

namespace omniloc::experiments {

/// "landmark_maps": accuracy of the landmark solvers (docs/landmarks.md, "Experiment landmark_maps").
///  (a) Paper 004's field (600 cm x 400 cm, the four goal posts as landmarks, the paper's frame): for each
///      closed-form solver a map of the mean position error under Gaussian bearing noise, N trials per
///      cell (map_<solver>.png, colour scale capped; maps_004.csv with every cell).
///  (b) Paper 004 table 1 in its layout: the five published true positions, mean estimates and mean
///      errors of the two-circle and three-point methods beside the published numbers (read from
///      results/reference/papers.json, key "004_table1_cm"): table1_004.json, table1_004.md.
///  (c) Paper 003's simulation: four landmarks, 8 m range, 1 m distance error, a seeded random path,
///      group fixes with and without voting (sim_003.json, sim_003_*.png).
/// --quick: coarse grid, few trials, short paths (well under 20 s).
int run_landmark_maps(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
