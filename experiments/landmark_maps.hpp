#pragma once
// "landmark_maps": accuracy of the landmark solvers (docs/landmarks.md, "Experiment landmark_maps").
//  (a) Paper 004's field (600 cm x 400 cm, the four goal posts as landmarks, the paper's frame): for each
//      closed-form solver a map of the mean position error under Gaussian bearing noise, N trials per
//      cell (map_<solver>.png, colour scale capped; maps_004.csv with every cell).
//  (b) Paper 004 table 1 in its layout: the five published true positions, mean estimates and mean
//      errors of the two-circle and three-point methods beside the published numbers (read from
//      results/reference/papers.json, key "004_table1_cm"): table1_004.json, table1_004.md.
//      /as_printed of table1_004.json: the set-up as printed (which posts each method's rule picks, the
//      bearing errors each published estimate implies, the camera's bearing noise estimated from the
//      published three-point results, a Monte Carlo of single measurements at that noise).
//  (c) Paper 003's simulation: four landmarks, 8 m range, 1 m distance error, a seeded random path,
//      group fixes with and without voting (sim_003.json, sim_003_*.png); /paper_memory/voting_cause
//      splits the voting run's error into the stale, remembered-coordinate and measurement parts.
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
  int asprinted_trials = 100000;  ///< per position and method: Monte Carlo of paper 004's set-up as printed
  int sigma_fit_trials = 5000;    ///< per position: common random numbers of the bearing-noise fit (bisection)
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

/// (b') Paper 004's set-up as printed (docs/landmarks.md, "(b) Paper 004 table 1"): which posts each
/// method's rule picks, the bearing errors each published estimate implies, the camera's bearing noise
/// estimated from the published three-point results, and a Monte Carlo of single measurements at that noise.

/// Paper 004's published table 1 (results/reference/papers.json, key "004_table1_cm", the one place
/// published numbers live): rows of true x, y, two-circle x, y, err, three-point x, y, err (cm).
struct Published004 {
  bool found = false;
  std::string note;  ///< why not found
  std::vector<std::array<double, 8>> rows;
};
Published004 published_table1_004();

/// The posts (indices into Field004::posts()) each method's rule picks at p (metres, paper frame).
struct PostChoice004 {
  /// Sec. 2.2: D1 = the goal whose pixels come nearest the image centre (the goal mouth nearest the
  /// robot), D1_L / D1_R its edges (L at the larger bearing), D2_L the edge of the other goal with fewer
  /// pixels to the centre (the nearer one). Order: D1_L, D1_R, D2_L.
  std::array<int, 3> two_circle{};
  /// Sec. 2.3: "initialisation as for the two-circle method", "the three nearest goal edges": nearest first.
  std::array<int, 3> three_point{};
  bool d1_tie = false;     ///< both goal mouths equally near (broken towards the yellow goal)
  bool third_tie = false;  ///< third and fourth nearest posts equally near (broken by index)
  bool same_set = false;   ///< both rules pick the same three posts
};
/// Ties (robot on the centre line, or on the goals' axis) go to the yellow goal and the post of lower
/// index; other_tie = true breaks every tie the other way (the paper does not say).
PostChoice004 choose_posts_004(const Field004& f, const Eigen::Vector2d& p, bool other_tie = false);

/// Bearing errors implied by an estimate: what the camera must have measured for an exact three-bearing
/// fix to land on `estimate` when the robot stands at `truth`. A fix uses only the bearing differences
/// (the heading absorbs a common offset), so these are given as differences. Angles in degrees.
struct ImpliedBearings {
  /// Change of the angle between posts (0, 1), (1, 2), (0, 2) (bearing of the first minus bearing of the
  /// second), seen from the estimate minus seen from the truth, wrapped to (-180, 180]. With the
  /// two-circle order: theta1 (D1_L, D1_R), theta2 (D1_R, D2_L), theta1 + theta2 (D1_L, D2_L).
  std::array<double, 3> diff_deg{};
  /// The smallest per-bearing errors (sum zero, least sum of squares) with these differences.
  std::array<double, 3> min_bearing_deg{};
  double norm_deg = 0.0;  ///< |min_bearing_deg|: under i.i.d. N(0, s) bearings, (norm / s)^2 is chi-square, 2 dof
};
ImpliedBearings implied_bearings(const std::array<Eigen::Vector2d, 3>& posts, const Eigen::Vector2d& truth, const Eigen::Vector2d& estimate);

/// The error of one post's bearing alone (the other two exact) whose fix comes nearest `estimate`: the
/// fix then lies on the circle through the other two posts and the truth; `point` is that circle's
/// point nearest the estimate, `error_deg` the bearing error of post j that puts the fix there (wrapped
/// to (-180, 180]), `miss` = |estimate - point| (metres). NaN when the circle degenerates to a line.
struct SinglePostFit {
  double error_deg = std::numeric_limits<double>::quiet_NaN();
  double miss = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector2d point = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
};
SinglePostFit single_post_fit(const std::array<Eigen::Vector2d, 3>& posts, const Eigen::Vector2d& truth, const Eigen::Vector2d& estimate,
                              std::size_t j);

struct AsPrintedRow {
  PostChoice004 choice;
  std::array<double, 4> post_dist_cm{};      ///< robot to each post
  ImpliedBearings implied_two_circle, implied_three_point;  ///< of the published estimates, with the posts of each rule
  std::array<SinglePostFit, 3> single_two_circle, single_three_point;  ///< per post of the rule (cm in the report)
  double far_goal_width_deg = 0.0;           ///< angle between the far goal's (D2's) two posts seen from the truth
  PostChoice004 alt_choice;                  ///< ties broken the other way (equal to choice without a tie)
  ImpliedBearings alt_two_circle, alt_three_point;
};
/// Monte Carlo at one bearing noise: per position, `trials` single measurements for each method
/// (independent draws), as the paper reports one real measurement per method and position.
struct AsPrintedMonteCarlo {
  double sigma_deg = 0.0;
  int trials = 0;
  std::array<double, 5> mean_err_two_circle_cm{}, mean_err_three_point_cm{};
  std::array<long, 5> n_ge_pub_two_circle{};    ///< two-circle trials with error >= the published two-circle error
  std::array<long, 5> n_ge_pub_three_point{};   ///< three-point trials with error >= the published three-point error
  std::array<double, 5> chi2_tail_two_circle{}, chi2_tail_three_point{};  ///< exp(-(norm / sigma)^2 / 2) of the implied bearings
  long n_ratio_ge_pub = 0;       ///< trials whose single-measurement ratio (like the scorecard's) >= the published one
  long n_two_circle_worse_all = 0;  ///< trials with the two-circle error above the three-point error at all five positions
  long n_both_edges_ge_pub = 0;  ///< trials with the two-circle error >= the published one at (75, 100) and (410, 83) at once
  double median_ratio = 0.0;
  long refused = 0;              ///< refused fixes (counted as errors above every published one)
};
struct AsPrinted004 {
  bool done = false;
  std::array<AsPrintedRow, 5> rows;
  double published_ratio = 0.0;              ///< (two-circle edge/centre ratio) / (three-point's), published
  double published_three_point_mean_cm = 0.0;
  double sigma_ml_deg = 0.0;                 ///< maximum likelihood from the five three-point implied bearings
  double sigma_mean_match_deg = 0.0;         ///< our mean three-point error over the five = the published mean
  AsPrintedMonteCarlo mc_mean_match, mc_ml;
};

/// (c) Paper 003's simulation: one condition (landmarks only or with a distractor; groups recognised
/// between consecutive frames or remembered), one path or all paths pooled.
struct Sim003Stats {
  std::vector<double> err_vote, err_novote, worst_fix;  ///< per frame, metres (worst_fix NaN without fixes; empty when pooled)
  std::vector<double> fix_errors;                       ///< every group fix of the voting run, metres
  int frames = 0, kept = 0, forced = 0, new_groups_vote = 0, new_groups_novote = 0;
};
/// Geometric dilution of a group fix (paper 003's circle intersection) with respect to errors of the
/// landmark coordinates: J[k] = d(fix position) / d(displacement of landmark k along dirs[k]), by central
/// differences at the given landmarks and bearings (metres per metre); `worst` = max |sum s_k J[k]| over
/// s_k = +-1, the largest first-order fix error when each landmark is off by at most 1 m along its
/// direction (the distance error of paper 003's simulation is measured along the line of sight). NaN when
/// the solver refuses.
struct FixDilution {
  std::array<Eigen::Vector2d, 3> J{};
  double worst = std::numeric_limits<double>::quiet_NaN();
};
FixDilution fix_dilution(const std::array<Eigen::Vector2d, 3>& landmarks, const std::array<double, 3>& bearings,
                         const std::array<Eigen::Vector2d, 3>& dirs);

/// Why the voting estimate errs (paper 003's "within about 1 m"), per frame of one condition's voting run.
/// The estimate of a frame is the voted average of some group fixes accepted at a "source" frame (this
/// frame, or an earlier one when the last position is kept). Its error splits into
///   estimate - truth = (estimate - truth at the source) + (truth at the source - truth now)  [stale part]
/// and, at the source, each averaged fix into its error from the remembered group coordinates alone
/// (fix from the remembered coordinates and the exact bearings) and from the measurement alone (fix
/// from the true landmark positions and that frame's noisy bearings).
struct VotingCauseFrame {
  static constexpr double kNaNc = std::numeric_limits<double>::quiet_NaN();
  int path = 0, frame = 0;
  double err = 0.0;             ///< |estimate - truth|, m
  bool accepted = false;        ///< a position was accepted this frame
  int fixes = 0;                ///< group fixes this frame
  int source_frame = -1;        ///< frame whose accepted position is the estimate (-1: the start pose)
  double stale = 0.0;           ///< |truth at the source - truth now|, m
  double source_err = 0.0;      ///< |estimate - truth at the source|, m
  double coord_err = kNaNc;     ///< at the source: error of the average of the remembered-coordinate-only fixes
  double meas_err = kNaNc;      ///< at the source: error of the average of the measurement-only fixes
  double dilution = kNaNc;      ///< at the source: largest, over the averaged fixes, first-order fix error (m) for
                                ///< distance errors of at most 1 m at each landmark's first sighting
  double radial_err_max = kNaNc;  ///< at the source: largest |radial error| of an averaged group's remembered coordinates, m
  double radial_pred = kNaNc;     ///< at the source: first-order fix error (average) from those radial errors alone, m
  double sum_err = kNaNc;         ///< at the source: |(coordinate part) + (measurement part)| as vectors: first-order check of the split
  int cluster = 0;              ///< fixes averaged at the source
};

struct Sim003Condition {
  std::string name;                ///< paper_consecutive, paper_memory, distractor_consecutive, distractor_memory
  Sim003Stats all;                 ///< every path pooled
  std::vector<Sim003Stats> paths;  ///< per path
  std::vector<Pose2> path0_truth;  ///< the true poses of path 0 (plotted)
  std::vector<VotingCauseFrame> cause;  ///< every frame of every path (memory conditions only; empty otherwise)
  std::vector<double> fix_coord_err, fix_meas_err, fix_dilution;  ///< per fix of every accepted frame's average, m
};

struct LandmarkMapsResult {
  Field004 field;
  SolverMaps maps;
  std::vector<Table1> tables;         ///< one per table_sigmas_deg
  std::vector<Sim003Condition> sim;
  Published004 published;             ///< paper 004 table 1 as read
  AsPrinted004 as_printed;            ///< done = false without the published table
  static constexpr double kSimRegionMargin = 1.0;  ///< m, plausible-region margin of the voting runs
};

LandmarkMapsResult compute_landmark_maps(const LandmarkMapsConfig& cfg);
/// landmark_maps.json, maps_004.csv, map_*.png, table1_004.{json,md}, sim_003.json, sim_003_*.png; the tables to `out`.
void write_landmark_maps_report(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, harness::RunDirectory& dir, std::ostream& out);

int run_landmark_maps(const ExperimentArgs& args, std::ostream& out);

}  // namespace omniloc::experiments
