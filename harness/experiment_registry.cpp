#include "harness/experiment.hpp"

// Add an experiment: include its header and append one line to the list below.

namespace omniloc::harness {

const std::vector<ExperimentInfo>& experiments() {
  static const std::vector<ExperimentInfo> list = {
  };
  return list;
}

}  // namespace omniloc::harness
