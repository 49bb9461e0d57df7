#pragma once
// The hybrid localizer of paper 002: MCL until it converges, then matching-optimisation tracking
// from its mean. Wrong-localisation detection: the deviation (upper quartile) of the line points from the field
// lines above a threshold AND |heading - compass| above a threshold for 5 consecutive frames
// restarts MCL.
#include "core/params.hpp"
#include "localization/matching.hpp"
#include "localization/mcl.hpp"
#include "localization/wrong_localisation.hpp"

namespace omniloc {

struct HybridParams {
  McLParams mcl;
  MatchingParams matching;
  /// Paper 002: deviation AND heading for 5 frames; plus the single-condition windows (see
  /// wrong_localisation.hpp), which catch the point-mirrored pose the AND misses.
  DetectionParams detection;
  static HybridParams from_json(JsonReader& r);
  static Json schema();
};

class HybridLocalizer : public Localizer {
 public:
  HybridLocalizer(const Field& field, const HybridParams& p, std::uint64_t seed, const std::string& cache_dir);
  std::string type() const override { return "hybrid"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  /// The global search's particles while it searches; nothing while the matcher tracks.
  DebugView debug_view(std::size_t max_particles) const override { return tracking_ ? DebugView{} : mcl_.debug_view(max_particles); }

 private:
  HybridParams p_;
  McLLocalizer mcl_;
  MatchingLocalizer tracker_;
  bool tracking_ = false;
  WrongLocalisationDetector detector_;
  int restarts_ = 0;
};

}  // namespace omniloc
