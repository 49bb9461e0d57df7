#pragma once
// "entropy_maps": image entropy over (exposure, gain) for normal light and strong sun (paper 002
// figures 6 and 11c) with the auto-adjust search path drawn on it, the entropy along the search line
// exposure = gain, and the frames before and after adjustment (figures 10 and 11), from the start
// pose of scenarios/paper/lighting_002*.json.
//
// Configuration: EntropyMapsConfig::from_args (grid and line steps; --quick coarser).
// Computation: compute_entropy_maps (renders and entropies per case).
// Report: write_entropy_maps_report (heat maps with the search path, frames, entropy_maps.json).
#include <cstdint>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "core/messages.hpp"
#include "experiments/experiment.hpp"

namespace omniloc::harness {
class RunDirectory;
}

namespace omniloc::experiments {

struct EntropyMapsConfig {
  /// {case name, scenario file}; the first case's scenario gives camera, vision and the robot.
  std::vector<std::pair<std::string, std::string>> cases;
  double lo = 2.0, hi = 40.0;  ///< exposure (ms) and gain range of the grid and the line
  double step = 2.0;           ///< grid step
  double line_step = 1.0;      ///< step along exposure = gain
  int cell_px = 20;            ///< heat-map cell size
  std::uint64_t seed = 1;
  bool quick = false;
  int grid_size() const;  ///< cells per side
  static EntropyMapsConfig from_args(const ExperimentArgs& args);
};

/// One lighting case.
struct EntropyCase {
  std::string name;
  std::vector<double> grid;  ///< entropy (nats), grid_size x grid_size, rows = gain from high (top) to low, columns = exposure
  double grid_best = -1, grid_best_exposure = 0, grid_best_gain = 0;
  std::vector<double> line_gain, line_entropy;  ///< along exposure = gain
  double line_best = -1, line_best_gain = 0;
  std::vector<std::pair<double, double>> search_path;  ///< the controller's (setting, entropy) steps
  std::string search_end;                               ///< its final event
  CameraSettings adjusted;                              ///< where it settled
  Image before, after;                                  ///< frames at the initial and the adjusted setting
  std::size_t points_before = 0, points_after = 0;      ///< line points found in them
};

struct EntropyMapsResult {
  std::vector<EntropyCase> cases;
};

EntropyMapsResult compute_entropy_maps(const EntropyMapsConfig& cfg);
/// entropy_<case>.png, frame_<case>_{before,after}.png, entropy_line.png, entropy_maps.json; the table to `out`.
void write_entropy_maps_report(const EntropyMapsConfig& cfg, const EntropyMapsResult& r, harness::RunDirectory& dir, std::ostream& out);

int run_entropy_maps(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
