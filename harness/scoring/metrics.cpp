#include "harness/scoring/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "harness/scoring/recovery.hpp"

namespace omniloc::harness {

RecallThreshold Scoring::threshold(double position_m, double heading_deg) {
  char key[64];
  std::snprintf(key, sizeof key, "%gcm_%gdeg", position_m * 100.0, heading_deg);
  return {position_m, heading_deg * kPi / 180.0, key};
}

std::vector<RecallThreshold> Scoring::default_recall() { return {threshold(0.10, 5), threshold(0.25, 10), threshold(0.50, 20)}; }

Scoring Scoring::from_json(const Json& j, const std::string& path, Json* effective) {
  Scoring sc;
  JsonReader r(j, path, effective);
  r.allow("comment");
  if (const Json* rec = r.raw("recall")) {
    const std::string at = r.child_path("recall");
    if (!rec->is_array() || rec->empty() || rec->size() > 8)
      throw ConfigError(at, json_brief(*rec), "1 to 8 thresholds [{\"position_m\": m, \"heading_deg\": deg}, ...]");
    sc.recall.clear();
    Json eff = Json::array();
    for (std::size_t i = 0; i < rec->size(); ++i) {
      Json e;
      JsonReader t((*rec)[i], json_child(at, i), &e);
      const double pos = t.positive("position_m", std::nullopt, 50.0);
      const double deg = t.positive("heading_deg", std::nullopt, 180.0);
      t.finish();
      sc.recall.push_back(threshold(pos, deg));
      for (std::size_t k = 0; k + 1 < sc.recall.size(); ++k)
        if (sc.recall[k].key == sc.recall.back().key) throw ConfigError(json_child(at, i), sc.recall.back().key, "distinct thresholds");
      eff.push_back(e);
    }
    if (effective) (*effective)["recall"] = eff;
  } else if (effective) {
    Json eff = Json::array();
    for (const auto& t : sc.recall) eff.push_back({{"position_m", t.position_m}, {"heading_deg", t.heading_rad * 180.0 / kPi}});
    (*effective)["recall"] = eff;
  }
  r.finish();
  return sc;
}

Json recall_json(const std::vector<FrameError>& answered, std::size_t frames, const Scoring& scoring) {
  Json j = Json::object();
  for (const auto& t : scoring.recall) {
    std::size_t in = 0;
    for (const auto& e : answered) in += t.contains(e);
    j[t.key] = frames ? Json(static_cast<double>(in) / static_cast<double>(frames)) : Json(nullptr);
  }
  return j;
}

std::string paper_table(const std::vector<TableRow>& rows) {
  std::size_t w = 4;
  for (const auto& r : rows) w = std::max(w, r.label.size());
  const std::string recall_key = rows.empty() ? std::string() : rows.front().recall_key;
  std::string out;
  char buf[640];
  std::snprintf(buf, sizeof buf, "%-*s | %8s %8s %8s | %8s %8s %8s | %8s %8s %8s | %6s %8s %8s %8s | %s\n", static_cast<int>(w), "case",
                "mean x", "mean y", "mean th", "std x", "std y", "std th", "max x", "max y", "max th", "frames", "answered", "rmse m",
                "p95 m", "within");
  out += buf;
  std::snprintf(buf, sizeof buf, "%-*s | %8s %8s %8s | %8s %8s %8s | %8s %8s %8s | %6s %8s %8s %8s | %s\n", static_cast<int>(w), "", "cm", "cm",
                "rad", "cm", "cm", "rad", "cm", "cm", "rad", "", "", "", "", recall_key.c_str());
  out += buf;
  for (const auto& r : rows) {
    const auto& s = r.s;
    // The share of frames answered beside every error over answered frames; the recall counts them all.
    char answered[32], recall[32];
    if (r.frames_total) {
      std::snprintf(answered, sizeof answered, "%7.1f%%", 100.0 * static_cast<double>(s.frames) / static_cast<double>(r.frames_total));
      std::snprintf(recall, sizeof recall, "%.1f%%", 100.0 * r.recall);
    } else {
      std::snprintf(answered, sizeof answered, "%8s", "-");
      std::snprintf(recall, sizeof recall, "-");
    }
    if (s.frames == 0) {
      std::snprintf(buf, sizeof buf, "%-*s | %-84s | %6zu %8s %8s %8s | %s\n", static_cast<int>(w), r.label.c_str(),
                    "no estimate: no error statistic", r.frames_total, answered, "-", "-", recall);
    } else {
      std::snprintf(buf, sizeof buf, "%-*s | %8.3f %8.3f %8.3f | %8.3f %8.3f %8.3f | %8.3f %8.3f %8.3f | %6zu %8s %8.3f %8.3f | %s\n",
                    static_cast<int>(w), r.label.c_str(), s.x_cm.mean, s.y_cm.mean, s.theta_rad.mean, s.x_cm.std, s.y_cm.std,
                    s.theta_rad.std, s.x_cm.max, s.y_cm.max, s.theta_rad.max, r.frames_total, answered, s.pos_rmse_m, s.pos_p95_m, recall);
    }
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

// The coverage of a block of frames: the share answered and the recall at each threshold over all
// `frames_total` frames; and its row of the terminal table.
void add_coverage(const std::vector<FrameError>& answered, std::size_t frames_total, const Scoring& scoring, Json& j, TableRow& row) {
  j["frames_total"] = frames_total;
  j["valid_fraction"] = frames_total ? Json(static_cast<double>(answered.size()) / static_cast<double>(frames_total)) : Json(nullptr);
  j["recall"] = recall_json(answered, frames_total, scoring);
  if (answered.empty())  // the reason beside the nulls
    j["why_null"] = frames_total ? "no estimate in any of the " + std::to_string(frames_total) + " scored frames" : std::string("no frame scored");
  row.frames_total = frames_total;
  row.recall_key = scoring.middle().key;
  const Json& mid = j["recall"][row.recall_key];
  row.recall = mid.is_number() ? mid.get<double>() : 0.0;
}

// When the localizer first answered, and first answered within the middle threshold (seconds from
// the run's start; null: never). What a global start costs.
void add_first_fix(const RobotRecord& robot, const Scoring& scoring, Json& rj) {
  Json first = nullptr, within = nullptr;
  const RecallThreshold& mid = scoring.middle();
  for (const auto& r : robot.frames) {
    if (!r.valid) continue;
    if (first.is_null()) first = r.t;
    if (mid.contains({r.t, r.est.x - r.truth.x, r.est.y - r.truth.y, angle_diff(r.est.theta, r.truth.theta)})) {
      within = r.t;
      break;
    }
  }
  rj["first_estimate_s"] = first;
  rj["first_within_s"] = within;
}

}  // namespace

Json rpe_json(const RobotRecord& robot, const std::vector<double>& moves) {
  const auto& f = robot.frames;
  // The frame period from the records (the camera rate), so that "one second" is a whole number of frames.
  std::vector<double> dts;
  for (std::size_t k = 1; k < f.size(); ++k) dts.push_back(f[k].t - f[k - 1].t);
  const double period = dts.empty() ? 0.0 : percentile(dts, 50);
  const auto block = [&](std::size_t step) {
    double st = 0, sr = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; step > 0 && i + step < f.size(); ++i) {
      const FrameRecord& a = f[i];
      const FrameRecord& b = f[i + step];
      if (!a.valid || !b.valid) continue;
      bool moved = false;
      // The simulation applies an event at the first physics step at or after its time: one at a
      // frame's own time moves the robot after that frame.
      for (double tm : moves) moved = moved || (tm >= a.t - 1e-9 && tm < b.t - 1e-9);
      if (moved) continue;
      const Pose2 e = a.truth.between(b.truth).inverse().compose(a.est.between(b.est));
      st += e.x * e.x + e.y * e.y;
      sr += e.theta * e.theta;
      ++n;
    }
    const double N = static_cast<double>(n);
    return Json{{"translation_rms_m", n ? Json(std::sqrt(st / N)) : Json(nullptr)},
                {"rotation_rms_rad", n ? Json(std::sqrt(sr / N)) : Json(nullptr)},
                {"pairs", n}};
  };
  const std::size_t second = period > 0 ? static_cast<std::size_t>(std::lround(1.0 / period)) : 0;
  return Json{{"frame", block(1)}, {"1s", block(second)}};
}

RobotScore score_robot(const RobotRecord& robot, const std::vector<Event>& events, double duration, const Scoring& scoring) {
  RobotScore score;
  std::vector<FrameError> errors;
  std::vector<ScoredFrame> scored;
  for (const auto& r : robot.frames) {
    scored.push_back({r.t, r.truth, r.est, r.valid});
    if (!r.valid) continue;
    errors.push_back({r.t, r.est.x - r.truth.x, r.est.y - r.truth.y, angle_diff(r.est.theta, r.truth.theta)});
  }
  score.all = summarize(errors);
  score.all_row.s = score.all;
  Json& rj = score.json;
  rj = to_json(score.all);
  rj["robot"] = robot.id;
  add_coverage(errors, robot.frames.size(), scoring, rj, score.all_row);
  add_first_fix(robot, scoring, rj);
  add_frame_statistics(robot, rj);
  std::vector<double> moves;
  for (const auto& e : events)
    if (e.robot == robot.id && (e.as<Kidnap>() || e.as<Teleport>())) moves.push_back(e.t);
  rj["rpe"] = rpe_json(robot, moves);
  const auto kidnaps = episodes(events, robot.id, duration, [](const Event& e) { return e.as<Kidnap>() != nullptr; });
  if (!kidnaps.empty()) rj["recovery"] = recovery_json(scored, kidnaps);
  // With kidnaps or covers, the papers' tables describe only the tracking phase: the frames before
  // each disruption and after the recovery from it (see split_tracking_phase).
  const auto disruptions = episodes(events, robot.id, duration, [](const Event& e) { return e.disrupts_tracking(); });
  if (!disruptions.empty()) {
    const PhaseSplit split = split_tracking_phase(scored, disruptions);
    score.tracking_phase = summarize(split.tracking);
    score.tracking_row.s = *score.tracking_phase;
    Json tp = to_json(*score.tracking_phase);
    add_coverage(split.tracking, split.frames, scoring, tp, score.tracking_row);
    tp["excluded_s"] = split.excluded_s;
    Json iv = Json::array();
    for (const auto& [a, b] : split.excluded) iv.push_back({a, b});
    tp["excluded"] = iv;
    rj["tracking_phase"] = tp;
  }
  return score;
}

}  // namespace omniloc::harness
