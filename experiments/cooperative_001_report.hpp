#pragma once
// Report of the experiment "cooperative_001": the markdown report (also printed), the CSV tables,
// the plots and cooperative_001.json, all from the result structs of cooperative_001_results.hpp
// and cooperative_001_rendered.hpp. Reads the published figures from results/reference/papers.json.
#include <cstdint>
#include <iosfwd>
#include <string>

#include "experiments/cooperative_001_config.hpp"
#include "experiments/cooperative_001_rendered.hpp"
#include "experiments/cooperative_001_results.hpp"

namespace omniloc::harness {
class RunDirectory;
}

namespace omniloc::experiments {

/// How the experiment was run.
struct CoopRun {
  std::string config_file;
  std::uint64_t seed = 1;
  bool quick = false;
  CoopTrials trials;     ///< the trial counts used (quick or full)
  double elapsed_s = 0;  ///< wall clock of configuration and computation
};

/// Writes cooperative_001.{json,md}, robots_vs_error.{csv,png}, field.png and, with `rendered`,
/// robots_vs_error_rendered.{csv,png} into `dir`, commits it and prints the markdown and the file list.
void write_cooperative_report(const Cooperative001Config& c, const CoopRun& run, const CoopDirectResult& direct, const CoopRenderedResult* rendered,
                              harness::RunDirectory& dir, std::ostream& out);

}  // namespace omniloc::experiments
