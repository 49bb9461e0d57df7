#pragma once
// "landmark_maps": accuracy of the landmark solvers (docs/landmarks.md, "Experiment landmark_maps").
//  (a) Paper 004's field (600 cm x 400 cm, the four goal posts as landmarks, the paper's frame): for each
//      closed-form solver a map of the mean position error under Gaussian bearing noise, N trials per
//      cell (map_<solver>.png, colour scale capped; maps_004.csv with every cell).
//  (b) Paper 004 table 1 in its layout: the five published true positions, mean estimates and mean
//      errors of the two-circle and three-point methods beside the published numbers (read from
//      results/reference/papers.json, key "004_table1_cm"): table1_004.json, table1_004.md.
//  (c) Paper 003's simulation: four landmarks, 8 m range, 1 m distance error, a seeded random path,
//      group fixes with and without voting (sim_003.json, sim_003_*.png).
// --quick: coarse grid, few trials, short paths (well under 20 s).
//
// Configuration: LandmarkMapsConfig::from_args. Computation: compute_landmark_maps (landmark_maps.cpp).
// Report: write_landmark_maps_report (landmark_maps_report.cpp).
#include <array>
#include <cstdint>
#include <iosfwd>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/pose2.hpp"
#include "experiments/experiment.hpp"
#include "localization/landmarks/landmark_fix.hpp"

namespace omniloc::harness {
class RunDirectory;
}

namespace omniloc::experiments {

struct LandmarkMapsConfig {
  std::uint64_t seed = 1;
  bool quick = false;
  double map_sigma = 0.0;  ///< rad, bearing noise of the maps (0.5 degrees)
  double cell_m = 0.1;     ///< map cell size
  int map_trials = 400;    ///< per cell
  int table_trials = 5000; ///< per table-1 position
  std::vector<double> table_sigmas_deg{0.5, 2.0};
  int sim_waypoints = 20, sim_paths = 20;  ///< paper 003 simulation
  double cap_cm = 30.0;    ///< colour scale cap of the maps
  static LandmarkMapsConfig from_args(const ExperimentArgs& args);
};

/// Paper 004's field in the paper's frame (metres; see landmark_maps.cpp for how its size is inferred).
struct Field004 {
  double length = 6.0;      // metres
  double width = 4.0;       // metres
  double goal_width = 1.0;  // metres, between the posts
  std::array<Eigen::Vector2d, 4> posts() const;
};

struct LandmarkSolver {
  const char* name;
  const char* label;
  landmarks::Fix (*fn)(std::span<const landmarks::BearingObs>);
  bool exact;  ///< a library solver (exact to rounding off its singular set), not a diagnostic
};
/// The compared solvers; the two-circle and three-point methods first (table 1 columns), eqs. (8)/(9) literal last.
const std::vector<LandmarkSolver>& landmark_solvers();

/// (a) Error maps over paper 004's field.
struct SolverMaps {
  int cols = 0, rows = 0;
  double cell_m = 0.0;
  int trials = 0;
  double sigma_deg = 0.0;
  std::vector<std::vector<double>> mean_cm;  ///< [solver][cell], NaN when every trial was refused
  std::vector<std::vector<double>> refused;  ///< [solver][cell], fraction of trials
  std::vector<double> max_diff_vs_total_cm;  ///< [solver], exact solvers: max |fix - total_like fix|
  std::vector<long> diff_over_1mm;           ///< [solver], trials where that difference exceeds 1 mm
  long compared = 0;
};

/// (b) Paper 004 table 1: the five published true positions (cm).
extern const std::array<Eigen::Vector2d, 5> kTable1True;
struct Table1Cell {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double mean_x = kNaN, mean_y = kNaN;  ///< cm, mean of the accepted estimates
  double mean_err = kNaN;               ///< cm, mean of |estimate - truth|
  double max_err = kNaN;                ///< cm
  int ok = 0, refused = 0;
};
struct Table1 {
  double sigma_deg = 0;
  std::vector<std::vector<Table1Cell>> rows;  ///< [position][solver]
};

/// (c) Paper 003's simulation: one condition (landmarks only or with a distractor; groups recognised
/// between consecutive frames or remembered), one path or all paths pooled.
struct Sim003Stats {
  std::vector<double> err_vote, err_novote, worst_fix;  ///< per frame, metres (worst_fix NaN without fixes; empty when pooled)
  std::vector<double> fix_errors;                       ///< every group fix of the voting run, metres
  int frames = 0, kept = 0, forced = 0, new_groups_vote = 0, new_groups_novote = 0;
};
struct Sim003Condition {
  std::string name;                ///< paper_consecutive, paper_memory, distractor_consecutive, distractor_memory
  Sim003Stats all;                 ///< every path pooled
  std::vector<Sim003Stats> paths;  ///< per path
  std::vector<Pose2> path0_truth;  ///< the true poses of path 0 (plotted)
};

struct LandmarkMapsResult {
  Field004 field;
  SolverMaps maps;
  std::vector<Table1> tables;         ///< one per table_sigmas_deg
  std::vector<Sim003Condition> sim;
  static constexpr double kSimRegionMargin = 1.0;  ///< m, plausible-region margin of the voting runs
};

LandmarkMapsResult compute_landmark_maps(const LandmarkMapsConfig& cfg);
/// landmark_maps.json, maps_004.csv, map_*.png, table1_004.{json,md}, sim_003.json, sim_003_*.png; the tables to `out`.
void write_landmark_maps_report(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, harness::RunDirectory& dir, std::ostream& out);

int run_landmark_maps(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
