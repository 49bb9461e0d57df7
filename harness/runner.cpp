#include "harness/runner.hpp"

#include <chrono>
#include <cmath>
#include <deque>
#include <cstdio>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>

#include "core/version.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/perception.hpp"
#include "harness/recovery.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "sim/motion.hpp"
#include "sim/sensors.hpp"
#include "sim/world.hpp"

namespace omniloc::harness {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

struct FrameRow {
  double t;
  int robot;
  Pose2 truth, est;
  bool valid, camera_ok, contact;
  std::string mode;
  std::size_t points;
  double match_error;
  std::map<std::string, double> extra;
  double render_ms, vision_ms, localize_ms;
};

// Per localized robot: its sensors, localizer and records.
struct Tracked {
  int id = 0;
  std::unique_ptr<sim::OdometrySensor> odometry;
  std::unique_ptr<sim::HeadingSensor> heading;
  bool has_heading = true;
  std::unique_ptr<Localizer> localizer;
  std::vector<FrameError> errors;
  std::vector<FrameRow> rows;
  std::vector<ScoredFrame> scored;
  std::string gt_tum, est_tum;
  double covered_until = -1.0;
  double occluded_until = -1.0;
  sim::OcclusionMask event_mask;
  bool paused = false;
  std::string last_mode;
  std::size_t frames = 0, valid = 0;
};

}  // namespace

std::string tum_line(double t, const Pose2& p) {
  char b[160];
  std::snprintf(b, sizeof b, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", t, p.x, p.y, std::sin(0.5 * p.theta), std::cos(0.5 * p.theta));
  return b;
}

RunResult run_scenario(const Scenario& sc, const RunOptions& opt) {
  const std::uint64_t seed = opt.seed.value_or(sc.seed);
  RunResult result;
  result.seed = seed;
  const std::string out_dir = opt.out_dir.empty() ? "results/runs/" + sc.name + "/" + std::to_string(seed) : opt.out_dir;
  RunDirectory dir(out_dir);

  const double dt = 1.0 / sc.physics_rate;
  sim::World world(sc.field, dt);
  std::map<int, std::unique_ptr<sim::MotionScript>> scripts;
  for (const auto& rc : sc.robots) {
    world.add_robot(rc.spec);
    scripts[rc.spec.id] = sim::MotionScript::from_json(rc.motion, rc.motion_path, derive_seed(seed, "motion/" + std::to_string(rc.spec.id)), &sc.field);
  }
  if (sc.has_ball) world.set_ball(sc.ball_position, sc.ball_velocity);

  // Localizers and sensors for each localized robot, each with its own random stream.
  Json effective = sc.effective;
  effective["seed"] = seed;
  const LocalizerInfo& info = localizer_info(sc.localizer.value("type", std::string()), "/localizer/type");
  std::vector<Tracked> tracked;
  for (int id : sc.localized_robots()) {
    const RobotConfig& rc = *sc.robot(id);
    Tracked tr;
    tr.id = id;
    tr.odometry = std::make_unique<sim::OdometrySensor>(rc.odometry, Rng::stream(seed, "odometry/" + std::to_string(id)));
    tr.heading = std::make_unique<sim::HeadingSensor>(rc.heading, Rng::stream(seed, "heading/" + std::to_string(id)));
    tr.has_heading = rc.has_heading_sensor;
    LocalizerContext ctx;
    ctx.field = &sc.field;
    ctx.seed = derive_seed(seed, "localizer/" + std::to_string(id));
    ctx.cache_dir = "results/cache";
    Json eff;
    tr.localizer = make_localizer(sc.localizer, "/localizer", ctx, &eff);
    effective["localizer"] = eff;
    tr.localizer->reset(info.needs_start_pose ? std::optional<Pose2>(rc.spec.start) : std::nullopt);
    tracked.push_back(std::move(tr));
  }
  auto perception = make_perception(sc, info.needs_vision || !opt.frames_dir.empty(), seed);
  // Camera latency: the image shows the world as it was `latency` seconds before the frame time.
  const double latency = sc.camera.value("latency_ms", 0.0) * 1e-3;
  std::deque<sim::WorldState> history;

  std::string events_log;
  auto log_event = [&](const Json& e) { events_log += e.dump() + "\n"; };
  std::size_t next_event = 0;
  Rng event_rng = Rng::stream(seed, "events");

  const long long n_frames = static_cast<long long>(std::floor(sc.duration * sc.camera_rate + 1e-9)) + 1;
  for (long long k = 0; k < n_frames; ++k) {
    const double t_frame = static_cast<double>(k) / sc.camera_rate;
    // Physics up to the frame time (the first frame is taken at t = 0 before any motion).
    while (world.time() < t_frame - 1e-9) {
      while (next_event < sc.events.size() && sc.events[next_event].t <= world.time() + 1e-9) {
        const EventConfig& e = sc.events[next_event++];
        Json ej{{"t", world.time()}, {"type", e.type}, {"robot", e.robot}};
        if (e.type == "teleport" || e.type == "kidnap") {
          const Pose2 target = sc.event_target(e, event_rng);
          world.teleport(e.robot, target);
          scripts[e.robot]->on_teleport();
          ej["pose"] = {target.x, target.y, target.theta};
        }
        if (e.type == "cover" || e.type == "kidnap") {
          for (auto& tr : tracked)
            if (tr.id == e.robot) tr.covered_until = world.time() + e.duration;
          ej["duration"] = e.duration;
        }
        if (e.type == "occlude") {
          for (auto& tr : tracked)
            if (tr.id == e.robot) {
              tr.occluded_until = world.time() + e.duration;
              tr.event_mask = e.mask;
            }
          ej["duration"] = e.duration;
          ej["fraction"] = e.mask.fraction();
        }
        if (e.type == "lights") {
          ej["level"] = e.level;
          ej["transition"] = e.transition;
        }
        log_event(ej);
      }
      const sim::WorldState ws = world.state();
      for (const auto& rc : sc.robots) {
        bool paused = false;
        for (const auto& tr : tracked) paused = paused || (tr.id == rc.spec.id && tr.paused);
        world.command(rc.spec.id, paused ? sim::DriveCommand{} : scripts[rc.spec.id]->command(ws, rc.spec.id, world.time()));
      }
      world.step();
      if (latency > 0) {
        history.push_back(world.state());
        while (history.size() > 1 && history[1].t <= world.time() - latency - 1e-9) history.pop_front();
      }
      for (auto& tr : tracked) {
        tr.odometry->accumulate(world.wheel_motion(tr.id));
        tr.heading->advance(dt);
      }
    }
    sim::WorldState ws = world.state();
    ws.lighting = sc.lighting_at(ws.t);
    for (auto& tr : tracked) {
      const sim::RobotState& truth = *ws.robot(tr.id);
      FrameConditions cond;
      cond.covered = ws.t < tr.covered_until;
      // Whole-run mask and event masks together (event masks may overlap the run's mask).
      cond.occlusion = sc.occlusion.robot_frame(truth.pose.theta);
      if (ws.t < tr.occluded_until)
        for (const auto& sct : tr.event_mask.robot_frame(truth.pose.theta)) cond.occlusion.push_back(sct);
      const Odometry odo = tr.odometry->read(ws.t);
      std::optional<double> heading;
      if (tr.has_heading) heading = tr.heading->read(ws.t, truth.pose.theta).heading;

      // What the camera saw: the newest state at least `latency` old (lighting as now).
      const sim::WorldState* seen = &ws;
      sim::WorldState past;
      if (latency > 0 && !history.empty() && history.front().t <= ws.t - latency + 1e-9) {
        past = history.front();
        for (const auto& h : history)
          if (h.t <= ws.t - latency + 1e-9) past = h;
        past.lighting = ws.lighting;
        seen = &past;
      }
      PerceptionOutput po = perception->observe(*seen, tr.id, ws.t, cond);
      if (!opt.frames_dir.empty() && po.image && k % opt.frames_every == 0) {
        char name[64];
        std::snprintf(name, sizeof name, "/r%d_%06lld.png", tr.id, k);
        write_png(*po.image, opt.frames_dir + name);
      }
      for (const auto& w : po.warnings) log_event(Json{{"t", ws.t}, {"type", "warning"}, {"robot", tr.id}, {"message", w}});
      for (const auto& n : po.notes)
        log_event(Json{{"t", ws.t}, {"type", "camera"}, {"robot", tr.id}, {"message", n}, {"exposure_ms", po.settings.exposure_ms}, {"gain", po.settings.gain}});
      if (po.stop_robot != tr.paused) log_event(Json{{"t", ws.t}, {"type", po.stop_robot ? "pause" : "resume"}, {"robot", tr.id}});
      tr.paused = po.stop_robot;
      const auto t0 = Clock::now();
      const Estimate est = tr.localizer->update(po.obs, odo, heading);
      const double loc_ms = ms_since(t0);

      ++tr.frames;
      std::map<std::string, double> extra = est.extra;
      if (po.image) {  // the camera settings the frame was taken with (exposure control, paper 002)
        extra["exposure_ms"] = po.settings.exposure_ms;
        extra["gain"] = po.settings.gain;
      }
      FrameRow row{ws.t, tr.id, truth.pose, est.pose, est.valid, po.obs.camera_ok, world.in_contact(tr.id), est.mode,
                   po.obs.line_points.size(), est.match_error, extra, po.render_ms, po.vision_ms, loc_ms};
      tr.rows.push_back(row);
      tr.gt_tum += tum_line(ws.t, truth.pose);
      tr.scored.push_back({ws.t, truth.pose, est.pose, est.valid});
      if (est.valid) {
        ++tr.valid;
        tr.est_tum += tum_line(ws.t, est.pose);
        tr.errors.push_back({ws.t, est.pose.x - truth.pose.x, est.pose.y - truth.pose.y, angle_diff(est.pose.theta, truth.pose.theta)});
      }
      if (est.mode != tr.last_mode) {
        log_event(Json{{"t", ws.t}, {"type", "mode"}, {"robot", tr.id}, {"mode", est.mode}});
        tr.last_mode = est.mode;
      }
    }
    if (opt.log && k % static_cast<long long>(std::max(1.0, 10 * sc.camera_rate)) == 0 && k > 0)
      *opt.log << "  t = " << ws.t << " s\n";
  }

  // Write the results.
  Json summary;
  summary["scenario"] = sc.name;
  summary["seed"] = seed;
  summary["localizer"] = info.type;
  summary["noise_profile"] = sc.noise.name;
  summary["duration_s"] = sc.duration;
  summary["camera_rate_hz"] = sc.camera_rate;
  summary["omniloc"] = build_info_json();  // provenance; the regression gates compare everything else
  std::vector<TableRow> rows;
  std::string csv = "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode,camera_ok,line_points,match_error,contact";
  std::set<std::string> extra_keys;
  for (const auto& tr : tracked)
    for (const auto& r : tr.rows)
      for (const auto& [k, v] : r.extra) extra_keys.insert(k);
  for (const auto& k : extra_keys) csv += "," + k;
  csv += "\n";
  std::string timing = "t,robot,render_ms,vision_ms,localize_ms\n";
  for (std::size_t i = 0; i < tracked.size(); ++i) {
    const Tracked& tr = tracked[i];
    for (const auto& r : tr.rows) {
      const double ex = r.est.x - r.truth.x, ey = r.est.y - r.truth.y, eth = angle_diff(r.est.theta, r.truth.theta);
      csv += fmt("%.4f", r.t) + "," + std::to_string(r.robot) + "," + fmt("%.5f", r.truth.x) + "," + fmt("%.5f", r.truth.y) + "," +
             fmt("%.5f", r.truth.theta) + "," + fmt("%.5f", r.est.x) + "," + fmt("%.5f", r.est.y) + "," + fmt("%.5f", r.est.theta) + "," +
             fmt("%.5f", ex) + "," + fmt("%.5f", ey) + "," + fmt("%.5f", eth) + "," + fmt("%.5f", std::hypot(ex, ey)) + "," +
             (r.valid ? "1" : "0") + "," + r.mode + "," + (r.camera_ok ? "1" : "0") + "," + std::to_string(r.points) + "," +
             fmt("%.6g", r.match_error) + "," + (r.contact ? "1" : "0");
      for (const auto& k : extra_keys) {
        auto it = r.extra.find(k);
        csv += "," + (it == r.extra.end() ? std::string() : fmt("%.6g", it->second));
      }
      csv += "\n";
      timing += fmt("%.4f", r.t) + "," + std::to_string(r.robot) + "," + fmt("%.4f", r.render_ms) + "," + fmt("%.4f", r.vision_ms) + "," +
                fmt("%.4f", r.localize_ms) + "\n";
    }
    const std::string suffix = i == 0 ? "" : "_r" + std::to_string(tr.id);
    dir.write("gt" + suffix + ".tum", tr.gt_tum);
    dir.write("est" + suffix + ".tum", tr.est_tum);
    RobotResult rr;
    rr.robot = tr.id;
    rr.all = summarize(tr.errors);
    rr.frames = tr.frames;
    rr.valid_frames = tr.valid;
    result.robots.push_back(rr);
    Json rj = to_json(rr.all);
    rj["robot"] = tr.id;
    rj["frames_total"] = tr.frames;
    rj["valid_fraction"] = tr.frames ? static_cast<double>(tr.valid) / tr.frames : 0.0;
    {
      // Vision statistics: line points per frame and frames without a usable match.
      double pts = 0;
      std::size_t coasting = 0, min_pts = tr.rows.empty() ? 0 : SIZE_MAX;
      for (const auto& r : tr.rows) {
        pts += static_cast<double>(r.points);
        min_pts = std::min(min_pts, r.points);
        coasting += r.mode == "coasting";
      }
      rj["line_points"] = {{"mean", tr.rows.empty() ? 0.0 : pts / tr.rows.size()}, {"min", min_pts}};
      rj["coasting_frames"] = coasting;
      // Failures stated, not averaged away: how often the localizer gave up its pose, and how many
      // valid frames were wrong (over 0.5 m or 0.35 rad) or point-mirrored (compass turned round).
      std::size_t restarts = 0, wrong = 0, mirrored = 0;
      for (const auto& r : tr.rows) {
        restarts += r.mode == "restart";
        if (!r.valid) continue;
        const double ep = std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y), et = std::fabs(angle_diff(r.est.theta, r.truth.theta));
        wrong += ep > 0.5 || et > 0.35;
        mirrored += std::hypot(r.est.x + r.truth.x, r.est.y + r.truth.y) < 0.5 && std::fabs(angle_diff(r.est.theta, r.truth.theta + kPi)) < 0.35 && ep > 0.5;
      }
      rj["relocalisations"] = restarts;
      rj["wrong_frames"] = wrong;
      rj["mirrored_frames"] = mirrored;
    }
    // Kidnap episodes of this robot: from each kidnap's uncovering to the next kidnap or the end.
    std::vector<Episode> episodes;
    for (const auto& e : sc.events)
      if (e.type == "kidnap" && e.robot == tr.id) episodes.push_back({e.t, e.t + e.duration, sc.duration + 1.0});
    for (std::size_t k = 0; k + 1 < episodes.size(); ++k) episodes[k].t_end = episodes[k + 1].t_kidnap;
    if (!episodes.empty()) {
      std::vector<EpisodeResult> res;
      for (const auto& e : episodes) res.push_back(score_episode(tr.scored, e));
      rj["recovery"] = recovery_summary(res);
      Json per = Json::array();
      for (std::size_t k = 0; k < res.size(); ++k)
        per.push_back({{"t_kidnap", episodes[k].t_kidnap}, {"recovered", res[k].recovered}, {"recovery_time_s", res[k].recovery_time},
                       {"false_recovery", res[k].false_recovery}, {"mirrored", res[k].mirrored}});
      rj["recovery"]["per_kidnap"] = per;
    }
    // With kidnaps or covers, the papers' tables describe only the tracking phase: the frames
    // before each disruption and after the recovery from it (see split_tracking_phase).
    std::vector<Episode> disruptions;
    std::optional<TableRow> phase_row;
    for (const auto& e : sc.events)
      if ((e.type == "kidnap" || e.type == "cover") && e.robot == tr.id) disruptions.push_back({e.t, e.t + e.duration, sc.duration + 1.0});
    for (std::size_t k = 0; k + 1 < disruptions.size(); ++k) disruptions[k].t_end = disruptions[k + 1].t_kidnap;
    if (!disruptions.empty()) {
      const PhaseSplit split = split_tracking_phase(tr.scored, disruptions);
      const ErrorSummary tracking = summarize(split.tracking);
      Json tp = to_json(tracking);
      tp["excluded_s"] = split.excluded_s;
      Json iv = Json::array();
      for (const auto& [a, b] : split.excluded) iv.push_back({a, b});
      tp["excluded"] = iv;
      rj["tracking_phase"] = tp;
      phase_row = TableRow{sc.name + " r" + std::to_string(tr.id) + " " + info.type + " (tracking phase)", tracking};
    }
    summary["robots"].push_back(rj);
    rows.push_back({sc.name + " r" + std::to_string(tr.id) + " " + info.type + (phase_row ? " (all frames)" : ""), rr.all});
    if (phase_row) rows.push_back(*phase_row);
  }
  dir.write("frames.csv", csv);
  dir.write("timing.csv", timing);
  dir.write("events.jsonl", events_log);
  dir.write("summary.json", summary.dump(2) + "\n");
  dir.write("config.json", effective.dump(2) + "\n");
  dir.write("field.json", sc.field.markings_json().dump() + "\n");
  dir.commit();

  result.out_dir = dir.final_dir();
  result.summary = summary;
  result.table = paper_table(rows);
  return result;
}

}  // namespace omniloc::harness
