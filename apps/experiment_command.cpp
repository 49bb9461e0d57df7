// `omniloc experiment`: a named experiment (experiments/).
#include "apps/commands.hpp"

#include <iostream>

#include "apps/command_support.hpp"
#include "core/path_check.hpp"
#include "experiments/experiment.hpp"

namespace omniloc::app {

const cli::Command kExperiment{"experiment", "NAME", 1, 1, "Run a named experiment (omniloc list).",
                               {{"--seed", "N", "seed"},
                                {"-o", "DIR", "output folder (default results/experiments/NAME); must not exist or be empty unless --overwrite"},
                                {"--overwrite", "", "replace what is at -o DIR"},
                                {"--quick", "", "the reduced version"},
                                {"--config", "FILE", "description file instead of scenarios/experiments/NAME.json"}}};

int cmd_experiment(const cli::Args& a) {
  check_output_target(a, true);
  for (const auto& e : experiments::all()) {
    if (e.name != a.positional[0]) continue;
    experiments::ExperimentArgs ea;
    if (a.has("--seed")) ea.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
    ea.out_dir = a.value("-o", "results/experiments/" + e.name);
    ea.quick = a.has("--quick");
    ea.config = a.value("--config");
    if (!ea.config.empty()) require_readable_file(ea.config, "--config", "an experiment description file (JSON)");
    return e.run(ea, std::cout);
  }
  throw UsageError("unknown experiment \"" + a.positional[0] + "\" (see omniloc list)");
}

}  // namespace omniloc::app
