#pragma once
// Global localisation of paper 000 (Xiong, Lu, Zheng): with the heading from an MTi, only (x, y) is
// searched. Sample points every 1 m from 1 m outside the field lines (315 on the 18 m x 12 m field);
// for each, E_k = mean e(d(o_i)) with e(t) = 1 - c^2 / (c^2 + t^2), c = 2.55 m; the 5 best are
// optimised by RPROP over (x, y, theta); the best is taken if its error is under a threshold,
// otherwise the grid is shifted by (0.35, 0.35) m and searched again, at most three passes, after
// which the smallest error recorded wins. Then matching-optimisation tracking with the odometry
// Kalman filter (as in paper 002). The MTi's drift is corrected by the vision heading while the match
// stays good, and wrong-localisation detection restarts the grid search.
#include <optional>
#include <vector>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "localization/matching.hpp"
#include "localization/wrong_localisation.hpp"

namespace omniloc {

struct GridGlobalParams {
  double spacing = 1.0;       ///< m between samples (paper 000)
  double outside = 1.0;       ///< m the grid reaches beyond the outer lines (paper 000: 21 x 15 = 315 samples)
  double shift = 0.35;        ///< m, (x, y) shift of the grid between passes (paper 000; NuBot: 0, 35, 70 cm)
  int passes = 3;             ///< paper 000
  int candidates = 5;         ///< best samples refined by RPROP (paper 000)
  double c_grid = 2.55;       ///< m, error scale of E_k (paper 000: c = 255 in cm)
  int grid_points = 100;      ///< line points (evenly subsampled) used for E_k
  int refine_iterations = 30; ///< at most this many RPROP iterations per candidate (paper 000: converges in ~10)
  double refine_c_start = 1.0;  ///< m: continuation of c from here down to matching.c while refining
  double accept_error = 0.12; ///< mean e(d) at matching.c under which a candidate is accepted at once
  double min_separation = 1.5;  ///< m: the 5 candidates are distinct samples at least this far apart
  bool record_traces = false; ///< keep each candidate's error per RPROP iteration (figures; costs time)
  // MTi drift correction (paper 000): while tracking with a median point deviation under good_deviation for
  // drift_frames frames, the offset between the vision heading and the MTi is learned with drift_gain
  // per frame. Corrections larger than detection.heading_threshold are not learned: that is a wrong
  // pose (or a turned-round compass), not drift, and is left to the detector.
  double good_deviation = 0.15;  ///< m, median point deviation (camera vibration puts far points a decimetre off)
  int drift_frames = 10;
  double drift_gain = 0.1;
  MatchingParams matching;
  DetectionParams detection;
  static GridGlobalParams from_json(JsonReader& r);
  static const ParamList<GridGlobalParams>& params();
  static Json schema();
};

/// Everything one global localisation did, for the pictures of paper 000 (figures 7 and 9).
struct GridSearchRecord {
  struct Sample {
    double x = 0, y = 0;  ///< m, world
    double error = 0;     ///< E_k
    int pass = 0;
  };
  struct Candidate {
    Pose2 start, result;
    double error = 0;               ///< after RPROP, mean e(d) at matching.c
    std::vector<double> trace;      ///< error per RPROP iteration
    int pass = 0;
  };
  double heading = 0;               ///< rad, MTi heading used
  std::vector<Sample> samples;
  std::vector<Candidate> candidates;
  int chosen = -1;                  ///< index into candidates
  int passes = 0;
  bool accepted = false;            ///< chosen error under accept_error
};

/// One global localisation on one frame's points (robot frame) with a known heading (world, rad).
GridSearchRecord grid_search(const Field& field, const FieldMap& map, const std::vector<Eigen::Vector2d>& points, double heading,
                             const GridGlobalParams& p);

class GridGlobalLocalizer : public Localizer {
 public:
  GridGlobalLocalizer(const Field& field, const GridGlobalParams& p, const std::string& cache_dir);
  std::string type() const override { return "grid_global"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  /// The most recent global localisation (empty before the first).
  const std::optional<GridSearchRecord>& last_search() const { return last_; }
  /// Learned MTi offset, rad (corrected heading = reading + offset).
  double heading_offset() const { return offset_; }

 private:
  GridGlobalParams p_;
  Field field_;
  MatchingLocalizer tracker_;
  WrongLocalisationDetector detector_;
  bool tracking_ = false;
  double offset_ = 0.0;
  int good_frames_ = 0, restarts_ = 0, searches_ = 0;
  std::optional<GridSearchRecord> last_;
};

}  // namespace omniloc
