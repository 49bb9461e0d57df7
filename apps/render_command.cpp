// `omniloc render`: the panorama one robot sees at one time.
#include "apps/commands.hpp"

#include <iostream>

#include "apps/command_support.hpp"
#include "harness/render_frame.hpp"
#include "harness/scenario.hpp"

namespace omniloc::app {

const cli::Command kRender{"render", "FILE", 1, 1, "Render the panorama robot ID sees at time t.",
                           {{"--t", "SECONDS", "time in [0, the scenario's duration] (default 0)"},
                            {"--robot", "ID", "robot id (default: the first localized robot)"},
                            {"--seed", "N", "seed (default: the scenario's)"},
                            {"--labels", "", "draw the classified colours"},
                            {"--points", "", "draw the detected line points"},
                            {"-o", "FILE.png", "output picture (required); an existing file only with --overwrite"},
                            {"--overwrite", "", "replace an existing -o file"}}};

int cmd_render(const cli::Args& a) {
  const std::string out = a.value("-o");
  if (out.empty()) throw UsageError("render needs -o frame.png");
  check_output_target(a, false);
  const auto s = harness::load_scenario(a.positional[0]);
  const double t = a.number("--t", 0.0, 0.0, s.duration);
  const int robot = static_cast<int>(a.integer("--robot", s.localized_robots().front(), 0, 99));
  if (!s.robot(robot)) throw UsageError("--robot needs the id of a robot of the scenario, got " + std::to_string(robot));
  const std::uint64_t seed = a.unsigned_integer("--seed", s.seed, kMaxSeed);
  harness::render_to_png(s, t, robot, seed, a.has("--labels"), out, a.has("--points"));
  std::cout << "wrote " << out << "\n";
  return 0;
}

}  // namespace omniloc::app
