// `omniloc list`: the names a scenario may use, and where the shipped files are.
#include "apps/commands.hpp"

#include <iostream>

#include "core/field.hpp"
#include "core/install_paths.hpp"
#include "experiments/experiment.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/scenario.hpp"
#include "sim/motion.hpp"

namespace omniloc::app {

const cli::Command kList{"list", "", 0, 0, "Field presets, motion scripts, event kinds, localizers, noise profiles, experiments.", {}};

int cmd_list(const cli::Args&) {
  std::cout << "field presets:";
  for (const auto& n : Field::preset_names()) std::cout << " " << n;
  std::cout << "\nmotion scripts:";
  for (const auto& n : sim::MotionScript::types()) std::cout << " " << n;
  std::cout << "\nnoise profiles:";
  for (const auto& n : harness::NoiseProfile::names()) std::cout << " " << n;
  std::cout << "\nevents:";
  for (const auto& n : harness::event_type_names()) std::cout << " " << n;
  std::cout << "\nlocalizers:\n";
  for (const auto& l : harness::localizers()) std::cout << "  " << l.type << " - " << l.description << "\n";
  std::cout << "experiments:\n";
  for (const auto& e : experiments::all()) std::cout << "  " << e.name << " - " << e.description << "\n";
  // Where the lists above came from (an installed package's share/omniloc or the source tree).
  std::cout << "shared files: " << share_dir().string() << "\n" << "data: " << data_dir() << "\n";
  return 0;
}

}  // namespace omniloc::app
