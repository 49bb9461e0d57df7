#include "harness/runner.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <ostream>

#include "core/atomic_file.hpp"
#include "core/version.hpp"
#include "external/external_localizer.hpp"
#include "harness/bound_cache.hpp"
#include "harness/cache/cache_dirs.hpp"
#include "harness/external_session.hpp"
#include "harness/frame_source.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/perception.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "harness/run_writer.hpp"
#include "harness/scoring/bound.hpp"
#include "harness/simulation.hpp"
#include "sim/render/camera_config.hpp"

namespace omniloc::harness {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A localized robot: its localizer (robot side) and what the run records of it.
struct Tracked {
  std::unique_ptr<Localizer> localizer;
  std::string last_mode;  // as written to events.jsonl
  RobotRecord record;
  bool start_pose_given = false;  // reset() got the true start pose (summary.json start_pose_given)
};

// One localizer per localized robot, each with its own random stream; tracking localizers start at
// the true start pose (the papers' set-up), and so do external ones that ask for it. `effective`
// gets the localizer's effective parameters. An external localizer's client is started here (its
// stderr log goes to `log_dir`, the run's staging folder) and told the camera the frames come from.
std::vector<Tracked> make_tracked(const Scenario& sc, std::uint64_t seed, const LocalizerInfo& info, const FrameSource& source,
                                  const std::string& log_dir, Json& effective) {
  std::vector<Tracked> tracked;
  for (int id : sc.localized_robots()) {
    Tracked tr;
    tr.record.id = id;
    LocalizerContext ctx;
    ctx.field = &sc.field;
    ctx.seed = derive_seed(seed, "localizer/" + std::to_string(id));
    ctx.cache_dir = build_cache_dir("fieldmaps");
    ctx.camera_latency = declared_camera_latency(sc);
    ctx.camera_mount_height = declared_camera_mount_height(sc);
    ctx.camera_vibration = declared_camera_vibration(sc);
    external::Session session;
    if (info.type == "external") {
      session = make_session(sc, id, source.client_camera(id), source.detects_blobs(), ctx.seed, log_dir);
      ctx.session = &session;
    }
    Json eff;
    tr.localizer = make_localizer(sc.localizer, ctx, &eff);
    effective["localizer"] = eff;
    tr.start_pose_given = info.needs_start_pose || tr.localizer->wants_start_pose();
    tr.localizer->reset(tr.start_pose_given ? std::optional<Pose2>(sc.robot(id)->spec.start) : std::nullopt);
    tracked.push_back(std::move(tr));
  }
  return tracked;
}

// What a localizer without vision sees of a frame that was perceived with a camera (a recording):
// what NoPerception gives a live run of it, so the replay writes the live run's files.
void without_vision(RobotFrame& r) {
  Observations o;
  o.t = r.obs.t;
  o.camera_ok = !r.covered;
  r.obs = std::move(o);
  r.settings.reset();
  r.events.clear();
  r.render_ms = r.vision_ms = 0.0;
}

// One camera frame of one localized robot: localize, record; returns the estimate.
Estimate robot_frame(Tracked& tr, const RobotFrame& rf, long long k, const RunOptions& opt, EventLog& log) {
  const int id = tr.record.id;
  const double t = rf.obs.t;
  if (!opt.frames_dir.empty() && rf.obs.image && k % opt.frames_every == 0) {
    char name[64];
    std::snprintf(name, sizeof name, "/r%d_%06lld.png", id, k);
    write_png(*rf.obs.image, opt.frames_dir + name);
  }
  for (const auto& line : rf.events) log.add_line(line);
  const auto t0 = Clock::now();
  const Estimate est = tr.localizer->update(rf.obs, rf.odometry, rf.heading);
  const double loc_ms = ms_since(t0);

  // What the bound reads of the frame by the one conversion a recording's frames go through too, so
  // that the bound cache's key of a run and of its recording agree (harness/bound_cache.hpp).
  FrameRecord row = bound_frame(rf);
  row.est = est.pose;
  row.valid = est.valid;
  row.contact = rf.contact;
  row.mode = est.mode;
  row.mode_label = est.mode_label;
  row.points = rf.obs.line_points.size();
  row.match_error = est.match_error;
  row.extra = est.extra;
  row.render_ms = rf.render_ms;
  row.vision_ms = rf.vision_ms;
  row.localize_ms = loc_ms;
  row.compute_ms = est.compute_ms;
  if (rf.settings) {  // the camera settings the frame was taken with (exposure control, paper 002)
    row.extra["exposure_ms"] = rf.settings->exposure_ms;
    row.extra["gain"] = rf.settings->gain;
  }
  tr.record.frames.push_back(std::move(row));
  const std::string mode = est.mode_label.empty() ? mode_name(est.mode) : est.mode_label;
  if (mode != tr.last_mode) {
    log.add(Json{{"t", t}, {"type", "mode"}, {"robot", id}, {"mode", mode}});
    tr.last_mode = mode;
  }
  return est;
}

// One line of view.jsonl (docs/viewer.md section 4, omniloc-view/1).
std::string view_line(const Tracked& tr, const RobotFrame& rf, long long k, const Estimate& est, std::size_t max_particles) {
  Json pts = Json::array();
  for (const auto& p : rf.obs.line_points) pts.push_back(Json::array({p.x(), p.y()}));
  Json j = {{"k", k}, {"t", rf.obs.t}, {"robot", tr.record.id}, {"line_points", std::move(pts)}};
  if (!rf.obs.blobs.empty()) {
    Json blobs = Json::array();
    for (const auto& b : rf.obs.blobs) blobs.push_back(external::blob_json(b));
    j["blobs"] = std::move(blobs);
  }
  // Estimate's default (the identity) and an external client's "none" (NaN) mean no covariance given.
  if (est.covariance.allFinite() && !est.covariance.isIdentity(0.0)) {
    Json cov = Json::array();
    for (int r = 0; r < 3; ++r) cov.push_back(Json::array({est.covariance(r, 0), est.covariance(r, 1), est.covariance(r, 2)}));
    j["covariance"] = std::move(cov);
  }
  const DebugView dv = tr.localizer->debug_view(max_particles);
  if (!dv.particles.empty()) {
    Json ps = Json::array();
    for (const auto& p : dv.particles) ps.push_back(Json::array({p[0], p[1], p[2], p[3]}));
    j["particles"] = std::move(ps);
  }
  if (!dv.points.empty()) {
    Json ps = Json::array();
    for (const auto& p : dv.points) ps.push_back(Json::array({p.x(), p.y()}));
    j["points"] = std::move(ps);
  }
  return j.dump() + "\n";
}

// Scores every robot and writes the result files; the table rows go to `result`.
// `localizer`: the name results carry; `external`: an external client's provenance (else null);
// `start_pose_given`: whether the localizer was reset with the true start pose.
void write_results(const Scenario& sc, std::uint64_t seed, const std::string& localizer, const Json& external, bool start_pose_given,
                   const std::vector<RobotRecord>& records, const EventLog& log, const Json& effective, const Json& provenance,
                   RunDirectory& dir, RunResult& result) {
  Json summary;
  summary["scenario"] = sc.name;
  summary["seed"] = seed;
  summary["localizer"] = localizer;
  // Tables must not pair a run that knew where it started with one that localized globally (tracking
  // from the true pose is a far easier task), so every run states which it was.
  summary["start_pose_given"] = start_pose_given;
  if (!external.is_null()) {
    summary["localizer_type"] = "external";
    summary["external"] = external;
  }
  summary["noise_profile"] = sc.noise.name;
  summary["duration_s"] = sc.duration;
  summary["camera_rate_hz"] = sc.camera_rate;
  // The recall thresholds every robot's "recall" block uses, and the one tables lead with.
  summary["scoring"] = {{"recall", sc.effective.contains("scoring") ? sc.effective["scoring"]["recall"] : Json::array()},
                        {"headline", sc.scoring.middle().key}};
  summary["omniloc"] = build_info_json();  // provenance; the regression gates compare everything else
  summary["omniloc"]["host"] = host_info_json();  // the machine the run ran on (reports quote it)
  // The renderer (OSMesa and a GPU draw slightly different pixels, docs/camera.md "GPUs") and, for a
  // replay, the recording the frames came from.
  for (auto it = provenance.begin(); it != provenance.end(); ++it) summary["omniloc"][it.key()] = it.value();
  std::vector<TableRow> rows;
  std::vector<std::vector<FrameBound>> bounds(records.size());
  // The bound's estimate-free part is the same for every localizer replaying these frames: kept once.
  const BoundCache bound_cache(bound_cache_from_env());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const RobotRecord& rec = records[i];
    const std::string suffix = i == 0 ? "" : "_r" + std::to_string(rec.id);
    dir.write("est" + suffix + ".tum", estimate_tum(rec));
    if (!rec.has_truth) {  // a log without ground truth: the estimates and the localizer's own figures only
      std::size_t valid = 0;
      for (const auto& f : rec.frames) valid += f.valid;
      summary["scored"] = false;
      summary["robots"].push_back({{"robot", rec.id},
                                   {"frames", rec.frames.size()},
                                   {"valid_frames", valid},
                                   {"scored", false},
                                   {"why", "the recording has no ground truth: nothing was scored"}});
      result.robots.push_back({rec.id, ErrorSummary{}, rec.frames.size(), valid});
      continue;
    }
    dir.write("gt" + suffix + ".tum", truth_tum(rec));
    RobotScore score = score_robot(rec, sc.events, sc.duration, sc.scoring);
    // The limit beside the score (harness/scoring/bound.hpp).
    BoundSetup bs = bound_setup(sc, rec.id, start_pose_given);
    if (score.json.contains("tracking_phase"))
      for (const auto& iv : score.json["tracking_phase"]["excluded"]) bs.excluded.emplace_back(iv[0].get<double>(), iv[1].get<double>());
    RobotBound rb = bound_robot_cached(rec, bs, bound_cache);
    score.json["bound"] = std::move(rb.bound);
    score.json["efficiency"] = std::move(rb.efficiency);
    score.json["efficiency_single_frame"] = std::move(rb.efficiency_single);
    bounds[i] = std::move(rb.frames);
    result.robots.push_back({rec.id, score.all, rec.frames.size(), score.all.frames});
    summary["robots"].push_back(score.json);
    const std::string label = sc.name + " r" + std::to_string(rec.id) + " " + localizer;
    score.all_row.label = label + (score.tracking_phase ? " (all frames)" : "");
    rows.push_back(score.all_row);
    if (score.tracking_phase) {
      score.tracking_row.label = label + " (tracking phase)";
      rows.push_back(score.tracking_row);
    }
  }
  dir.write("frames.csv", frames_csv(records, bounds));
  dir.write("timing.csv", timing_csv(records));
  dir.write("events.jsonl", log.text());
  dir.write("summary.json", summary.dump(2) + "\n");
  dir.write("config.json", effective.dump(2) + "\n");
  dir.write("field.json", sc.field.markings_json().dump() + "\n");
  dir.commit();
  result.summary = summary;
  result.table = rows.empty() && !records.empty() ? "no ground truth in the frames: estimates written, nothing scored\n" : paper_table(rows);
}

}  // namespace

RunResult run_frames(const Scenario& sc, std::uint64_t seed, FrameSource& source, const RunOptions& opt, const Json& provenance) {
  return run_frames_after_hello(sc, seed, source, [&source](bool, Json&) -> FrameSource& { return source; }, opt, provenance);
}

RunResult run_frames_after_hello(const Scenario& sc, std::uint64_t seed, const FrameSource& hello, const FramesFor& frames, const RunOptions& opt,
                                 Json provenance) {
  RunResult result;
  result.seed = seed;
  RunDirectory dir(opt.out_dir.empty() ? "results/runs/" + sc.name + "/" + std::to_string(seed) : opt.out_dir);

  EventLog log;
  Json effective = sc.effective;
  effective["seed"] = seed;
  const LocalizerInfo& info = localizer_info(sc.localizer);
  std::vector<Tracked> tracked = make_tracked(sc, seed, info, hello, dir.staging(), effective);
  bool wants_images = false;
  for (const auto& tr : tracked)
    if (const auto* ext = dynamic_cast<const external::ExternalLocalizer*>(tr.localizer.get()); ext && ext->wants_image()) wants_images = true;
  FrameSource& source = frames(wants_images, provenance);
  for (auto& tr : tracked) tr.record.has_truth = source.has_ground_truth();
  if (wants_images && !source.has_images())
    throw ConfigError("/localizer", "a client that asked for images (ready.wants_image)",
                      "frames with images: this recording was made without them (omniloc record --images)");
  const bool strip = opt.replay && !info.needs_vision;
  // Streamed into the staging folder: 60 s with 200 particles a frame is about 38 MB.
  std::unique_ptr<StreamFile> view;
  if (opt.debug_view) view = std::make_unique<StreamFile>((std::filesystem::path(dir.staging()) / "view.jsonl").string());

  // perceive (the source) -> localize -> record, at every camera frame (the first at t = 0 before any motion).
  while (auto frame = source.next()) {
    for (const auto& line : frame->events) log.add_line(line);
    if (frame->robots.size() != tracked.size())
      throw RuntimeFailure("frame " + std::to_string(frame->k) + " has " + std::to_string(frame->robots.size()) + " robots, the run localizes " +
                           std::to_string(tracked.size()));
    for (std::size_t i = 0; i < tracked.size(); ++i) {
      if (strip) without_vision(frame->robots[i]);
      const Estimate est = robot_frame(tracked[i], frame->robots[i], frame->k, opt, log);
      if (view) view->write(view_line(tracked[i], frame->robots[i], frame->k, est, opt.debug_particles));
    }
    if (opt.log && frame->k % static_cast<long long>(std::max(1.0, 10 * sc.camera_rate)) == 0 && frame->k > 0)
      *opt.log << "  t = " << frame->t << " s\n";
  }
  for (auto& tr : tracked) tr.localizer->finish();  // an external client must end cleanly, or the run fails
  if (view) view->close();
  const std::string name = tracked.empty() ? info.type : tracked.front().localizer->name();
  const Json external = tracked.empty() ? Json(nullptr) : tracked.front().localizer->provenance();
  const bool start_pose_given = !tracked.empty() && tracked.front().start_pose_given;
  std::vector<RobotRecord> records;
  for (auto& tr : tracked) records.push_back(std::move(tr.record));
  write_results(sc, seed, name, external, start_pose_given, records, log, effective, provenance, dir, result);
  result.out_dir = dir.final_dir();
  return result;
}

RunResult run_scenario(const Scenario& sc, const RunOptions& opt) {
  const std::uint64_t seed = opt.seed.value_or(sc.seed);
  const LocalizerInfo& info = localizer_info(sc.localizer);
  LiveSource source(sc, seed, info.needs_vision || !opt.frames_dir.empty());
  Json provenance = Json::object();
  if (const auto dev = source.perception().render_device()) {
    provenance["render"] = dev->to_json();
    if (opt.log) *opt.log << "  rendering on " << dev->line() << "\n";
  }
  return run_frames(sc, seed, source, opt, provenance);
}

}  // namespace omniloc::harness
