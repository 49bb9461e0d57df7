#pragma once
// "global_figures": one global localisation of paper 000 on a rendered frame (figure 7: each grid
// sample's E_k as grey level, the best five marked; figure 9: RPROP error against iteration for the
// five candidates) and one MCL convergence as a particle-cloud sequence, from the robot standing at
// the first kidnap target of scenarios/paper/kidnap_000.json.
//
// Configuration: GlobalFiguresConfig::from_args. Computation: compute_global_figures (the grid
// search record, the MCL errors and particle snapshots). Report: write_global_figures_report.
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "core/field.hpp"
#include "core/pose2.hpp"
#include "experiments/experiment.hpp"
#include "localization/grid_global.hpp"
#include "localization/localizer.hpp"

namespace omniloc::harness {
class RunDirectory;
}

namespace omniloc::experiments {

struct GlobalFiguresConfig {
  std::string scenario_file;  ///< its first event is the kidnap whose target the robot stands at
  std::uint64_t seed = 1;
  int mcl_frames = 16;                       ///< MCL updates after the first (frame 0)
  std::vector<int> snapshots{0, 1, 2, 4, 8, 16};  ///< frames whose particle cloud is drawn (six tiles)
  static GlobalFiguresConfig from_args(const ExperimentArgs& args);
};

struct GlobalFiguresResult {
  Field field;
  Pose2 truth;
  double heading = 0;  ///< rad, the MTi heading given to the grid search
  std::size_t line_points = 0;
  GridGlobalParams grid_params;
  GridSearchRecord record;
  struct McLFrame {
    int frame = 0;
    double spread_m = 0, error_m = 0;
    LocalizerMode mode = LocalizerMode::kNone;
  };
  std::vector<McLFrame> mcl;  ///< frames 0..mcl_frames
  struct Snapshot {
    int frame = 0;
    double error_m = 0;
    std::vector<Pose2> particles;
  };
  std::vector<Snapshot> snapshots;
  const GridSearchRecord::Candidate& chosen() const;
  double position_error() const;  ///< m, of the chosen candidate
};

GlobalFiguresResult compute_global_figures(const GlobalFiguresConfig& cfg);
/// figure7_grid_errors.png, figure9_rprop_traces.png, mcl_particles.png, global_figures.json; the candidates to `out`.
void write_global_figures_report(const GlobalFiguresConfig& cfg, const GlobalFiguresResult& r, harness::RunDirectory& dir, std::ostream& out);

int run_global_figures(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
