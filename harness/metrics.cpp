#include "harness/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "harness/recovery.hpp"

namespace omniloc::harness {

namespace {
AxisStats stats(const std::vector<double>& v) {
  AxisStats a;
  if (v.empty()) return a;
  double s = 0, s2 = 0, m = 0;
  for (double x : v) {
    s += x;
    m = std::max(m, x);
  }
  a.mean = s / v.size();
  for (double x : v) s2 += (x - a.mean) * (x - a.mean);
  a.std = std::sqrt(s2 / v.size());
  a.max = m;
  return a;
}
}  // namespace

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p / 100.0 * (v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (pos - i) * (v[i + 1] - v[i]);
}

ErrorSummary summarize(const std::vector<FrameError>& errors) {
  ErrorSummary s;
  s.frames = errors.size();
  if (errors.empty()) return s;
  std::vector<double> ax, ay, at, pos;
  double se2 = 0, st2 = 0, sum_pos = 0;
  for (const auto& e : errors) {
    ax.push_back(std::fabs(e.ex) * 100.0);
    ay.push_back(std::fabs(e.ey) * 100.0);
    at.push_back(std::fabs(e.eth));
    pos.push_back(std::hypot(e.ex, e.ey));
    sum_pos += pos.back();
    se2 += e.ex * e.ex + e.ey * e.ey;
    st2 += e.eth * e.eth;
  }
  s.x_cm = stats(ax);
  s.y_cm = stats(ay);
  s.theta_rad = stats(at);
  s.pos_mean_m = sum_pos / errors.size();
  s.pos_rmse_m = std::sqrt(se2 / errors.size());
  s.theta_rmse_rad = std::sqrt(st2 / errors.size());
  s.pos_p50_m = percentile(pos, 50);
  s.pos_p90_m = percentile(pos, 90);
  s.pos_p95_m = percentile(pos, 95);
  s.pos_max_m = *std::max_element(pos.begin(), pos.end());
  return s;
}

Json to_json(const ErrorSummary& s) {
  auto axis = [](const AxisStats& a) { return Json{{"mean", a.mean}, {"std", a.std}, {"max", a.max}}; };
  return Json{{"frames", s.frames},
              {"x_cm", axis(s.x_cm)},
              {"y_cm", axis(s.y_cm)},
              {"theta_rad", axis(s.theta_rad)},
              {"position_m", {{"mean", s.pos_mean_m}, {"rmse", s.pos_rmse_m}, {"p50", s.pos_p50_m}, {"p90", s.pos_p90_m}, {"p95", s.pos_p95_m}, {"max", s.pos_max_m}}},
              {"theta_rmse_rad", s.theta_rmse_rad}};
}

std::string paper_table(const std::vector<TableRow>& rows) {
  std::size_t w = 4;
  for (const auto& r : rows) w = std::max(w, r.label.size());
  std::string out;
  char buf[512];
  std::snprintf(buf, sizeof buf, "%-*s | %8s %8s %8s | %8s %8s %8s | %8s %8s %8s | %6s %8s %8s\n", static_cast<int>(w), "case",
                "mean x", "mean y", "mean th", "std x", "std y", "std th", "max x", "max y", "max th", "frames", "rmse m", "p95 m");
  out += buf;
  std::snprintf(buf, sizeof buf, "%-*s | %8s %8s %8s | %8s %8s %8s | %8s %8s %8s |\n", static_cast<int>(w), "", "cm", "cm", "rad",
                "cm", "cm", "rad", "cm", "cm", "rad");
  out += buf;
  for (const auto& r : rows) {
    const auto& s = r.s;
    std::snprintf(buf, sizeof buf, "%-*s | %8.3f %8.3f %8.3f | %8.3f %8.3f %8.3f | %8.3f %8.3f %8.3f | %6zu %8.3f %8.3f\n",
                  static_cast<int>(w), r.label.c_str(), s.x_cm.mean, s.y_cm.mean, s.theta_rad.mean, s.x_cm.std, s.y_cm.std,
                  s.theta_rad.std, s.x_cm.max, s.y_cm.max, s.theta_rad.max, s.frames, s.pos_rmse_m, s.pos_p95_m);
    out += buf;
  }
  return out;
}

namespace {

// Frames of a run's tracking-quality figures: line points per frame and frames without a usable
// match; then how often the localizer gave up its pose, and how many valid frames were wrong (over
// 0.5 m or 0.35 rad) or point-mirrored (compass turned round).
void add_frame_statistics(const RobotRecord& robot, Json& rj) {
  double pts = 0;
  std::size_t coasting = 0, min_pts = robot.frames.empty() ? 0 : SIZE_MAX;
  for (const auto& r : robot.frames) {
    pts += static_cast<double>(r.points);
    min_pts = std::min(min_pts, r.points);
    coasting += r.mode == LocalizerMode::kCoasting;
  }
  rj["line_points"] = {{"mean", robot.frames.empty() ? 0.0 : pts / robot.frames.size()}, {"min", min_pts}};
  rj["coasting_frames"] = coasting;
  std::size_t restarts = 0, wrong = 0, mirrored = 0;
  for (const auto& r : robot.frames) {
    restarts += r.mode == LocalizerMode::kRestart;
    if (!r.valid) continue;
    const double ep = std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y), et = std::fabs(angle_diff(r.est.theta, r.truth.theta));
    wrong += ep > 0.5 || et > 0.35;
    mirrored += std::hypot(r.est.x + r.truth.x, r.est.y + r.truth.y) < 0.5 && std::fabs(angle_diff(r.est.theta, r.truth.theta + kPi)) < 0.35 && ep > 0.5;
  }
  rj["relocalisations"] = restarts;
  rj["wrong_frames"] = wrong;
  rj["mirrored_frames"] = mirrored;
}

// Episodes of `robot` from the events that `pick` selects: each from its event to the next one or
// past the run's end.
template <class Pick>
std::vector<Episode> episodes(const std::vector<Event>& events, int robot, double duration, Pick pick) {
  std::vector<Episode> out;
  for (const auto& e : events)
    if (e.robot == robot && pick(e)) out.push_back({e.t, e.t + e.duration(), duration + 1.0});
  for (std::size_t k = 0; k + 1 < out.size(); ++k) out[k].t_end = out[k + 1].t_kidnap;
  return out;
}

Json recovery_json(const std::vector<ScoredFrame>& scored, const std::vector<Episode>& kidnaps) {
  std::vector<EpisodeResult> res;
  for (const auto& e : kidnaps) res.push_back(score_episode(scored, e));
  Json j = recovery_summary(res);
  Json per = Json::array();
  for (std::size_t k = 0; k < res.size(); ++k)
    per.push_back({{"t_kidnap", kidnaps[k].t_kidnap}, {"recovered", res[k].recovered}, {"recovery_time_s", res[k].recovery_time},
                   {"false_recovery", res[k].false_recovery}, {"mirrored", res[k].mirrored}});
  j["per_kidnap"] = per;
  return j;
}

}  // namespace

RobotScore score_robot(const RobotRecord& robot, const std::vector<Event>& events, double duration) {
  RobotScore score;
  std::vector<FrameError> errors;
  std::vector<ScoredFrame> scored;
  std::size_t valid = 0;
  for (const auto& r : robot.frames) {
    scored.push_back({r.t, r.truth, r.est, r.valid});
    if (!r.valid) continue;
    ++valid;
    errors.push_back({r.t, r.est.x - r.truth.x, r.est.y - r.truth.y, angle_diff(r.est.theta, r.truth.theta)});
  }
  score.all = summarize(errors);
  Json& rj = score.json;
  rj = to_json(score.all);
  rj["robot"] = robot.id;
  rj["frames_total"] = robot.frames.size();
  rj["valid_fraction"] = robot.frames.empty() ? 0.0 : static_cast<double>(valid) / robot.frames.size();
  add_frame_statistics(robot, rj);
  const auto kidnaps = episodes(events, robot.id, duration, [](const Event& e) { return e.as<Kidnap>() != nullptr; });
  if (!kidnaps.empty()) rj["recovery"] = recovery_json(scored, kidnaps);
  // With kidnaps or covers, the papers' tables describe only the tracking phase: the frames before
  // each disruption and after the recovery from it (see split_tracking_phase).
  const auto disruptions = episodes(events, robot.id, duration, [](const Event& e) { return e.disrupts_tracking(); });
  if (!disruptions.empty()) {
    const PhaseSplit split = split_tracking_phase(scored, disruptions);
    score.tracking_phase = summarize(split.tracking);
    Json tp = to_json(*score.tracking_phase);
    tp["excluded_s"] = split.excluded_s;
    Json iv = Json::array();
    for (const auto& [a, b] : split.excluded) iv.push_back({a, b});
    tp["excluded"] = iv;
    rj["tracking_phase"] = tp;
  }
  return score;
}

}  // namespace omniloc::harness
