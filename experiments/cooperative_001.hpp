#pragma once
// Experiment "cooperative_001": paper 001's simulation (Xu, Xie, Wang, Ni, J. Image and Graphics
// 2012, section 6): five robots observe a ball rolling across a 6 m x 4 m field, share their
// sightings over a simulated radio network and fuse them in Hough space (localization/cooperative/).
// docs/cooperative.md has the results.
//
// Configuration: cooperative_001_config.hpp (the description file, shared set-up).
// Computation: compute_cooperative_direct (this file: "true ball + Gaussian noise", the paper's
// mode) and compute_cooperative_rendered (cooperative_001_rendered.hpp: every robot's own camera).
// Results: cooperative_001_results.hpp (what the direct mode measures).
// Report: cooperative_001_report.hpp (markdown, CSV, plots, JSON from the two results).
#include <array>
#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "experiments/cooperative_001_config.hpp"
#include "experiments/cooperative_001_results.hpp"
#include "experiments/cooperative_001_rendered.hpp"
#include "experiments/experiment.hpp"
#include "experiments/report_format.hpp"
#include "localization/cooperative/hough_ball.hpp"
#include "localization/cooperative/particle_core.hpp"

namespace omniloc::experiments {

/// The direct-noise mode with trial counts `n`.
CoopDirectResult compute_cooperative_direct(const Cooperative001Config& c, const CoopTrials& n, std::uint64_t seed);

/// Runs the experiment (args.config or the default file), writes cooperative_001.{json,md},
/// robots_vs_error.{png,csv}, field.png (and with "rendered": robots_vs_error_rendered.{png,csv})
/// into args.out_dir and prints the tables.
int run_cooperative_001(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
