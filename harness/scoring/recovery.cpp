#include "harness/scoring/recovery.hpp"

#include <algorithm>
#include <cmath>

namespace omniloc::harness {

namespace {
bool good(const ScoredFrame& f, const RecoveryCriteria& c) {
  return f.valid && std::hypot(f.est.x - f.truth.x, f.est.y - f.truth.y) < c.pos_tol &&
         std::fabs(angle_diff(f.est.theta, f.truth.theta)) < c.theta_tol;
}
bool wrong(const ScoredFrame& f, const RecoveryCriteria& c) {
  return f.valid && (std::hypot(f.est.x - f.truth.x, f.est.y - f.truth.y) > c.wrong_pos ||
                     std::fabs(angle_diff(f.est.theta, f.truth.theta)) > c.wrong_theta);
}
bool mirror(const ScoredFrame& f, const RecoveryCriteria& c) {
  return std::hypot(f.est.x + f.truth.x, f.est.y + f.truth.y) < c.mirror_pos &&
         std::fabs(angle_diff(f.est.theta, f.truth.theta + kPi)) < c.mirror_theta;
}
}  // namespace

EpisodeResult score_episode(const std::vector<ScoredFrame>& frames, const Episode& e, const RecoveryCriteria& c) {
  EpisodeResult r;
  std::vector<const ScoredFrame*> ep;
  for (const auto& f : frames)
    if (f.t >= e.t_uncover - 1e-9 && f.t < e.t_end) ep.push_back(&f);
  // Recovery: first frame from which every frame for `hold` seconds is good (and the run lasts that long).
  for (std::size_t i = 0; i < ep.size() && !r.recovered; ++i) {
    if (!good(*ep[i], c)) continue;
    std::size_t j = i;
    while (j < ep.size() && ep[j]->t < ep[i]->t + c.hold - 1e-9 && good(*ep[j], c)) ++j;
    const bool held = (j < ep.size() && ep[j]->t >= ep[i]->t + c.hold - 1e-9) || (j == ep.size() && ep.back()->t >= ep[i]->t + c.hold - 1e-9);
    if (held) {
      r.recovered = true;
      r.recovery_time = ep[i]->t - e.t_uncover;
      for (std::size_t k = i; k < ep.size(); ++k)
        r.after.push_back({ep[k]->t, ep[k]->est.x - ep[k]->truth.x, ep[k]->est.y - ep[k]->truth.y, angle_diff(ep[k]->est.theta, ep[k]->truth.theta)});
    }
  }
  // False recovery: a valid but wrong estimate held for `wrong_hold` seconds.
  for (std::size_t i = 0; i < ep.size(); ++i) {
    if (!wrong(*ep[i], c)) continue;
    std::size_t j = i;
    bool all_mirror = true;
    while (j < ep.size() && wrong(*ep[j], c)) {
      all_mirror = all_mirror && mirror(*ep[j], c);
      ++j;
    }
    const double span = ep[j - 1]->t - ep[i]->t;
    if (span >= c.wrong_hold - 1e-9) {
      r.false_recovery = true;
      r.mirrored = r.mirrored || all_mirror;
    }
    i = j - 1;
  }
  return r;
}

PhaseSplit split_tracking_phase(const std::vector<ScoredFrame>& frames, const std::vector<Episode>& disruptions, const RecoveryCriteria& c) {
  PhaseSplit p;
  for (const auto& e : disruptions) {
    const EpisodeResult r = score_episode(frames, e, c);
    const double to = r.recovered ? e.t_uncover + r.recovery_time : e.t_end;
    p.excluded.emplace_back(e.t_kidnap, to);
    // An episode never recovered reaches past the run's end (t_end); count only the time it covers.
    const double end = frames.empty() ? to : std::min(to, frames.back().t);
    p.excluded_s += std::max(0.0, end - e.t_kidnap);
  }
  for (const auto& f : frames) {
    const bool out = std::any_of(p.excluded.begin(), p.excluded.end(), [&](const auto& iv) { return f.t >= iv.first - 1e-9 && f.t < iv.second - 1e-9; });
    if (out) continue;
    ++p.frames;
    if (f.valid) p.tracking.push_back({f.t, f.est.x - f.truth.x, f.est.y - f.truth.y, angle_diff(f.est.theta, f.truth.theta)});
  }
  return p;
}

Json recovery_summary(const std::vector<EpisodeResult>& results) {
  std::size_t rec = 0, fals = 0, mir = 0;
  std::vector<double> times;
  std::vector<FrameError> after;
  for (const auto& r : results) {
    if (r.recovered) {
      ++rec;
      times.push_back(r.recovery_time);
      after.insert(after.end(), r.after.begin(), r.after.end());
    }
    fals += r.false_recovery;
    mir += r.mirrored;
  }
  Json j{{"episodes", results.size()}, {"recovered", rec},
         {"recovered_fraction", results.empty() ? Json(nullptr) : Json(static_cast<double>(rec) / results.size())},
         {"false_recoveries", fals}, {"mirrored", mir}};
  if (!times.empty()) {
    double s = 0;
    for (double t : times) s += t;
    j["recovery_time_s"] = {{"median", percentile(times, 50)}, {"mean", s / times.size()}, {"max", *std::max_element(times.begin(), times.end())}};
  } else {  // no episode recovered: no time to state (null, never absent, so that a gate sees it)
    j["recovery_time_s"] = {{"median", nullptr}, {"mean", nullptr}, {"max", nullptr}};
  }
  j["after_recovery"] = to_json(summarize(after));
  if (after.empty()) j["after_recovery"]["why_null"] = rec ? "no frame with an estimate after recovery" : "no kidnap recovered";
  return j;
}

}  // namespace omniloc::harness
