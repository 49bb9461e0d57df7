#pragma once
#include "experiments/experiment.hpp"

namespace omniloc::experiments {

/// "global_figures": one global localisation of paper 000 on a rendered frame (figure 7: each grid
/// sample's E_k as grey level, the best five marked; figure 9: RPROP error against iteration for the
/// five candidates) and one MCL convergence as a particle-cloud sequence, from the robot standing at
/// the first kidnap target of scenarios/paper/kidnap_000.json.
int run_global_figures(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
