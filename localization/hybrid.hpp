#pragma once
// The hybrid localizer of paper 002: MCL until it converges, then matching-optimisation tracking
// from its mean. Wrong-localisation detection: the mean deviation of the line points from the field
// lines above a threshold AND |heading - compass| above a threshold for 5 consecutive frames
// restarts MCL.
#include "localization/matching.hpp"
#include "localization/mcl.hpp"

namespace omniloc {

struct HybridParams {
  McLParams mcl;
  MatchingParams matching;
  double deviation_threshold = 0.25;  ///< m, mean point distance to the nearest line
  double heading_threshold = 0.35;    ///< rad, |tracked heading - compass|
  int consecutive = 5;                ///< paper 002: both conditions for this many frames
  /// Extension: the paper's AND misses a point-mirrored pose (the lines fit perfectly there, only the
  /// compass disagrees, by pi) and a kidnap that keeps the heading. Either condition alone for this
  /// many frames also restarts MCL (0 = off, the strict paper rule).
  int heading_only_frames = 15;
  int deviation_only_frames = 30;
  static HybridParams from_json(JsonReader& r);
};

class HybridLocalizer : public Localizer {
 public:
  HybridLocalizer(const Field& field, const HybridParams& p, std::uint64_t seed, const std::string& cache_dir);
  std::string type() const override { return "hybrid"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;

 private:
  HybridParams p_;
  McLLocalizer mcl_;
  MatchingLocalizer tracker_;
  bool tracking_ = false;
  int suspicious_ = 0, bad_heading_ = 0, bad_deviation_ = 0;
  int restarts_ = 0;
};

}  // namespace omniloc
