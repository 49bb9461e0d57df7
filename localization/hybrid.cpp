#include "localization/hybrid.hpp"

#include <cmath>

namespace omniloc {

Json HybridParams::schema() {
  Json s = params_schema(DetectionParams::params());
  s["mcl"] = {{"type", "object"}, {"description", "the global MCL stage"}, {"properties", McLParams::schema()}, {"additionalProperties", false}};
  s["matching"] = {{"type", "object"}, {"description", "the matching tracker"}, {"properties", MatchingParams::schema()}, {"additionalProperties", false}};
  return s;
}

HybridParams HybridParams::from_json(JsonReader& r) {
  HybridParams p;
  if (auto m = r.object("mcl")) {
    p.mcl = McLParams::from_json(*m);
    m->finish();
  }
  if (auto m = r.object("matching")) {
    p.matching = MatchingParams::from_json(*m);
    m->finish();
  }
  p.detection = DetectionParams::from_json(r);
  return p;
}

HybridLocalizer::HybridLocalizer(const Field& field, const HybridParams& p, std::uint64_t seed, const std::string& cache_dir)
    : p_(p), mcl_(field, p.mcl, seed, cache_dir), tracker_(field, p.matching, cache_dir), detector_(p.detection) {}

void HybridLocalizer::reset(const std::optional<Pose2>& start) {
  mcl_.reset(std::nullopt);
  tracking_ = false;
  detector_.reset();
  if (start) {
    tracker_.reset(start);
    tracking_ = true;
  }
}

Estimate HybridLocalizer::update(const Observations& obs, const Odometry& odo, std::optional<double> heading) {
  Estimate e;
  if (!tracking_) {
    e = mcl_.update(obs, odo, heading);
    if (mcl_.converged()) {
      // MCL's mean is good to a few decimetres: refine it with a continuation match before tracking.
      const auto pts = subsample(obs.line_points, p_.matching.max_points);
      Pose2 start = e.pose;
      if (static_cast<int>(pts.size()) >= p_.matching.min_points) {
        MatchingParams refine = p_.matching;
        refine.c_start = std::max(refine.c, 1.0);
        start = rprop_match(tracker_.map(), pts, e.pose, refine, 60).pose;
      }
      tracker_.reset(start);
      e.pose = start;
      tracking_ = true;
      detector_.reset();
      e.mode = LocalizerMode::kConverged;
    }
  } else {
    e = tracker_.track(obs, odo);
    // Wrong-localisation detection (paper 002).
    if (e.mode == LocalizerMode::kTracking) {
      const double dev = line_deviation(tracker_.map(), subsample(obs.line_points, p_.matching.max_points), e.pose, p_.detection.deviation_quantile);
      e.extra["deviation_m"] = dev;
      if (detector_.update(dev, e.pose, heading)) {
        mcl_.reset(std::nullopt);
        tracking_ = false;
        ++restarts_;
        e.valid = false;
        e.mode = LocalizerMode::kRestart;
      }
    }
  }
  e.extra["restarts"] = restarts_;
  return e;
}

}  // namespace omniloc
