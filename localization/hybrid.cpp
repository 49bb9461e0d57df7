#include "localization/hybrid.hpp"

#include <cmath>

namespace omniloc {

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
  p.deviation_threshold = r.positive("deviation_threshold", p.deviation_threshold, 10.0);
  p.heading_threshold = r.positive("heading_threshold", p.heading_threshold, 3.2);
  p.consecutive = static_cast<int>(r.integer("consecutive", p.consecutive, 1, 1000));
  p.heading_only_frames = static_cast<int>(r.integer("heading_only_frames", p.heading_only_frames, 0, 100000));
  p.deviation_only_frames = static_cast<int>(r.integer("deviation_only_frames", p.deviation_only_frames, 0, 100000));
  return p;
}

HybridLocalizer::HybridLocalizer(const Field& field, const HybridParams& p, std::uint64_t seed, const std::string& cache_dir)
    : p_(p), mcl_(field, p.mcl, seed, cache_dir), tracker_(field, p.matching, cache_dir) {}

void HybridLocalizer::reset(const std::optional<Pose2>& start) {
  mcl_.reset(std::nullopt);
  tracking_ = false;
  suspicious_ = 0;
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
      suspicious_ = 0;
      e.mode = "converged";
    }
  } else {
    e = tracker_.track(obs, odo);
    // Wrong-localisation detection (paper 002).
    if (e.mode == "tracking") {
      const auto pts = subsample(obs.line_points, p_.matching.max_points);
      double dev = 0;
      const double c = std::cos(e.pose.theta), s = std::sin(e.pose.theta);
      for (const auto& o : pts) dev += tracker_.map().distance({e.pose.x + c * o.x() - s * o.y(), e.pose.y + s * o.x() + c * o.y()});
      dev /= static_cast<double>(pts.size());
      const bool bad_dev = dev > p_.deviation_threshold;
      const bool bad_head = heading && std::fabs(angle_diff(e.pose.theta, *heading)) > p_.heading_threshold;
      suspicious_ = bad_dev && bad_head ? suspicious_ + 1 : 0;
      bad_heading_ = bad_head ? bad_heading_ + 1 : 0;
      bad_deviation_ = bad_dev ? bad_deviation_ + 1 : 0;
      e.extra["deviation_m"] = dev;
      const bool restart = suspicious_ >= p_.consecutive || (p_.heading_only_frames > 0 && bad_heading_ >= p_.heading_only_frames) ||
                           (p_.deviation_only_frames > 0 && bad_deviation_ >= p_.deviation_only_frames);
      if (restart) {
        mcl_.reset(std::nullopt);
        tracking_ = false;
        suspicious_ = bad_heading_ = bad_deviation_ = 0;
        ++restarts_;
        e.valid = false;
        e.mode = "restart";
      }
    }
  }
  e.extra["restarts"] = restarts_;
  return e;
}

}  // namespace omniloc
