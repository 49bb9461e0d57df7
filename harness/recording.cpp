#include "harness/recording.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <tuple>
#include <ostream>
#include <sstream>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "core/version.hpp"
#include "external/external_localizer.hpp"
#include "external/sha256.hpp"
#include "harness/external_session.hpp"
#include "harness/frames_reader.hpp"
#include "harness/gzip.hpp"
#include "harness/image_file.hpp"
#include "harness/recording_limits.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/render_frame.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {



std::string image_name(int robot, long long k) {
  char name[64];
  std::snprintf(name, sizeof name, "images/r%d_%06lld.png", robot, k);
  return name;
}

Json pose_json(const Pose2& p) { return Json::array({p.x, p.y, p.theta}); }

Json robot_to_json(const RobotFrame& r) {
  Json pts = Json::array();
  pts.get_ref<Json::array_t&>().reserve(r.obs.line_points.size());
  for (const auto& p : r.obs.line_points) pts.push_back(Json::array({p.x(), p.y()}));
  Json blobs = Json::array();
  for (const auto& b : r.obs.blobs) blobs.push_back(external::blob_json(b));  // olp/1's frame.blobs format
  Json j = {{"robot", r.id},
            {"odometry", pose_json(r.odometry.delta)},
            {"heading", r.heading ? Json(*r.heading) : Json(nullptr)},
            {"camera_ok", r.obs.camera_ok},
            {"line_points", std::move(pts)},
            {"covered", r.covered},
            {"camera", r.settings ? Json{{"exposure_ms", r.settings->exposure_ms}, {"gain", r.settings->gain}} : Json(nullptr)},
            {"stop_robot", r.stop_robot},
            {"contact", r.contact}};
  // Optional, absent when empty (most frames): blobs and this robot's perception events.
  if (!blobs.empty()) j["blobs"] = std::move(blobs);
  if (!r.events.empty()) {
    Json events = Json::array();
    for (const auto& e : r.events) events.push_back(Json::parse(e));
    j["events"] = std::move(events);
  }
  if (r.truth) j["truth"] = pose_json(*r.truth);
  return j;
}

// Strict readers of frames.jsonl values: `at` names the file, line and JSON path.
[[noreturn]] void bad(const std::string& at, const Json& v, const std::string& expected) { throw ConfigError(at, json_brief(v), expected); }

const Json& member(const Json& o, const char* key, const std::string& at) {
  const auto it = o.find(key);
  if (it == o.end()) throw ConfigError(json_child(at, key), "nothing", "a value (docs/recording.md)");
  return *it;
}

double finite(const Json& v, const std::string& at) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) bad(at, v, "a finite number");
  return v.get<double>();
}

using namespace recording_limits;  // harness/recording_limits.hpp: docs/recording.md section 7

double within(const Json& v, const std::string& at, double lo, double hi, const char* unit) {
  const double x = finite(v, at);
  if (x < lo || x > hi) {
    char range[160];
    std::snprintf(range, sizeof range, "a number from %g to %g %s (docs/recording.md section 7)", lo, hi, unit);
    bad(at, v, range);
  }
  return x;
}
double length(const Json& v, const std::string& at) { return within(v, at, -kMaxLength, kMaxLength, "m"); }
double angle(const Json& v, const std::string& at) { return within(v, at, -kMaxAngle, kMaxAngle, "rad"); }

bool boolean(const Json& v, const std::string& at) {
  if (!v.is_boolean()) bad(at, v, "true or false");
  return v.get<bool>();
}

// A pose or an odometry step: [x, y, theta], metres and radians, each within the limits above.
Pose2 pose(const Json& v, const std::string& at) {
  if (!v.is_array() || v.size() != 3) bad(at, v, "[x, y, theta]");
  return Pose2(length(v[0], json_child(at, std::size_t{0})), length(v[1], json_child(at, std::size_t{1})), angle(v[2], json_child(at, std::size_t{2})));
}

ColourClass colour_of(const Json& v, const std::string& at) {
  if (v == "yellow") return kYellow;
  if (v == "blue") return kBlue;
  if (v == "red") return kRed;
  bad(at, v, "\"yellow\", \"blue\" or \"red\"");
}

Blob::Kind kind_of(const Json& v, const std::string& at) {
  if (v == "region") return Blob::Kind::kRegion;
  if (v == "left_edge") return Blob::Kind::kLeftEdge;
  if (v == "right_edge") return Blob::Kind::kRightEdge;
  bad(at, v, "\"region\", \"left_edge\" or \"right_edge\"");
}

Blob blob_from_json(const Json& j, const std::string& at) {
  if (!j.is_object()) bad(at, j, "a blob object (docs/protocol.md, frame.blobs)");
  Blob b;
  b.colour = colour_of(member(j, "colour", at), json_child(at, "colour"));
  b.kind = kind_of(member(j, "kind", at), json_child(at, "kind"));
  b.bearing = angle(member(j, "bearing", at), json_child(at, "bearing"));
  b.left_bearing = angle(member(j, "left_bearing", at), json_child(at, "left_bearing"));
  b.right_bearing = angle(member(j, "right_bearing", at), json_child(at, "right_bearing"));
  const Json& d = member(j, "distance", at);
  if (!d.is_null()) {
    b.distance = within(d, json_child(at, "distance"), 0.0, kMaxLength, "m");
    b.has_distance = true;
  }
  const Json& area = member(j, "area_px", at);
  if (!area.is_number_integer() || area.get<long long>() < 0 || area.get<long long>() > (1LL << 31) - 1)
    bad(json_child(at, "area_px"), area, "a pixel count");
  b.area_px = area.get<int>();
  b.left_occluded = boolean(member(j, "left_occluded", at), json_child(at, "left_occluded"));
  b.right_occluded = boolean(member(j, "right_occluded", at), json_child(at, "right_occluded"));
  return b;
}

RobotFrame robot_from_json(const Json& j, const std::string& at, double t, const RecordedRobot& expected, bool truth) {
  if (!j.is_object()) bad(at, j, "an object for robot " + std::to_string(expected.id));
  RobotFrame r;
  const Json& id = member(j, "robot", at);
  if (!id.is_number_integer() || id.get<long long>() != expected.id) bad(json_child(at, "robot"), id, "robot " + std::to_string(expected.id) + " (recording.json's order)");
  r.id = expected.id;
  r.odometry.t = t;
  r.odometry.delta = pose(member(j, "odometry", at), json_child(at, "odometry"));
  const Json& h = member(j, "heading", at);
  if (!h.is_null()) r.heading = angle(h, json_child(at, "heading"));
  r.obs.t = t;
  r.obs.camera_ok = boolean(member(j, "camera_ok", at), json_child(at, "camera_ok"));
  const std::string lp_at = json_child(at, "line_points");
  const Json& lp = member(j, "line_points", at);
  if (!lp.is_array()) bad(lp_at, lp, "an array of [x, y]");
  r.obs.line_points.reserve(lp.size());
  for (std::size_t i = 0; i < lp.size(); ++i) {
    const Json& p = lp[i];
    const std::string p_at = json_child(lp_at, i);
    if (!p.is_array() || p.size() != 2) bad(p_at, p, "[x, y]: two finite numbers, metres, robot frame");
    r.obs.line_points.emplace_back(length(p[0], json_child(p_at, std::size_t{0})), length(p[1], json_child(p_at, std::size_t{1})));
  }
  if (const auto b = j.find("blobs"); b != j.end()) {
    if (!b->is_array()) bad(json_child(at, "blobs"), *b, "an array of blobs");
    for (std::size_t i = 0; i < b->size(); ++i) r.obs.blobs.push_back(blob_from_json((*b)[i], json_child(json_child(at, "blobs"), i)));
  }
  if (const auto c = j.find("covered"); c != j.end()) r.covered = boolean(*c, json_child(at, "covered"));
  if (const auto c = j.find("camera"); c != j.end() && !c->is_null()) {
    if (!c->is_object()) bad(json_child(at, "camera"), *c, "{\"exposure_ms\", \"gain\"} or null");
    const std::string c_at = json_child(at, "camera");
    r.settings = CameraSettings{within(member(*c, "exposure_ms", c_at), json_child(c_at, "exposure_ms"), 0.0, kMaxExposureMs, "ms"),
                                within(member(*c, "gain", c_at), json_child(c_at, "gain"), 0.0, kMaxGain, "gain units")};
  }
  if (const auto s = j.find("stop_robot"); s != j.end()) r.stop_robot = boolean(*s, json_child(at, "stop_robot"));
  if (const auto e = j.find("events"); e != j.end()) {
    if (!e->is_array()) bad(json_child(at, "events"), *e, "an array of event objects");
    for (std::size_t i = 0; i < e->size(); ++i) {
      if (!(*e)[i].is_object()) bad(json_child(json_child(at, "events"), i), (*e)[i], "an event object");
      r.events.push_back((*e)[i].dump());
    }
  }
  if (const auto c = j.find("contact"); c != j.end()) r.contact = boolean(*c, json_child(at, "contact"));
  if (truth) r.truth = pose(member(j, "truth", at), json_child(at, "truth"));
  return r;
}

std::shared_ptr<const Image> read_png(const std::string& path) {
  // The file was found readable before (why_not_readable_file): what fails here is its content.
  return std::make_shared<Image>(read_png_rgb(path));
}

}  // namespace

Json frame_to_json(const FrameData& f) {
  Json robots = Json::array();
  for (const auto& r : f.robots) robots.push_back(robot_to_json(r));
  Json j = {{"k", f.k}, {"t", f.t}, {"robots", std::move(robots)}};
  if (!f.events.empty()) {
    Json events = Json::array();
    for (const auto& e : f.events) events.push_back(Json::parse(e));
    j["events"] = std::move(events);
  }
  return j;
}

FrameData frame_from_json(const Json& j, const std::string& at, const std::vector<RecordedRobot>& robots, bool truth) {
  if (!j.is_object()) bad(at, j, "a frame object {\"k\", \"t\", \"events\", \"robots\"}");
  FrameData f;
  const Json& k = member(j, "k", at);
  if (!k.is_number_integer() || k.get<long long>() < 0) bad(json_child(at, "k"), k, "the frame number");
  f.k = k.get<long long>();
  f.t = within(member(j, "t", at), json_child(at, "t"), 0.0, kMaxTime, "s");
  if (const auto e = j.find("events"); e != j.end()) {
    if (!e->is_array()) bad(json_child(at, "events"), *e, "an array of event objects");
    for (std::size_t i = 0; i < e->size(); ++i) {
      if (!(*e)[i].is_object()) bad(json_child(json_child(at, "events"), i), (*e)[i], "an event object");
      f.events.push_back((*e)[i].dump());
    }
  }
  const Json& rs = member(j, "robots", at);
  if (!rs.is_array() || rs.size() != robots.size())
    bad(json_child(at, "robots"), rs, "one object per recorded robot (" + std::to_string(robots.size()) + ")");
  for (std::size_t i = 0; i < robots.size(); ++i)
    f.robots.push_back(robot_from_json(rs[i], json_child(json_child(at, "robots"), i), f.t, robots[i], truth));
  return f;
}

RecordResult record_scenario(const Scenario& sc, const RecordOptions& opt) {
  RecordResult result;
  result.seed = opt.seed.value_or(sc.seed);
  RunDirectory dir(opt.out_dir.empty() ? "results/recordings/" + sc.name + "/" + std::to_string(result.seed) : opt.out_dir);
  LiveSource source(sc, result.seed, true);
  if (opt.images) {
    std::error_code ec;
    fs::create_directories(fs::path(dir.staging()) / "images", ec);
    if (ec) throw IoError("cannot create folder", (fs::path(dir.staging()) / "images").string(), ec.message());
  }
  std::string frames;
  std::string timing = "k,robot,render_ms,vision_ms\n";  // wall time: the one file that differs between recordings of a run
  while (auto f = source.next()) {
    frames += frame_to_json(*f).dump() + "\n";
    for (const auto& r : f->robots) {
      char row[128];
      std::snprintf(row, sizeof row, "%lld,%d,%.4f,%.4f\n", f->k, r.id, r.render_ms, r.vision_ms);
      timing += row;
    }
    if (opt.images)
      for (const auto& r : f->robots)
        if (r.obs.image) {
          const std::string path = (fs::path(dir.staging()) / image_name(r.id, f->k)).string();
          write_png(*r.obs.image, path);
          std::error_code ec;
          const auto bytes = fs::file_size(path, ec);
          if (!ec) result.image_bytes += bytes;
        }
    ++result.frames;
    if (opt.log && f->k % static_cast<long long>(std::max(1.0, 10 * sc.camera_rate)) == 0 && f->k > 0) *opt.log << "  t = " << f->t << " s\n";
  }
  Json scenario = sc.input;
  scenario["name"] = sc.name;
  scenario["seed"] = result.seed;
  Json robots = Json::array();
  for (int id : sc.localized_robots())
    robots.push_back({{"id", id}, {"start", pose_json(sc.robot(id)->spec.start)}, {"camera", source.client_camera(id)}, {"blobs", source.detects_blobs()}});
  const Json header = {{"format", kRecordingFormat},
                       {"omniloc", build_info_json()},
                       {"name", sc.name},
                       {"seed", result.seed},
                       {"scenario", scenario},
                       {"scenario_source", sc.source},
                       {"field", sc.input.contains("field") ? sc.input["field"] : Json(sc.field.name)},
                       {"field_markings", field_for_client(sc.field)},
                       {"field_fingerprint", sc.field.fingerprint()},
                       {"camera_rate_hz", sc.camera_rate},
                       {"duration_s", sc.duration},
                       {"frames", result.frames},
                       {"frames_file", kFramesFile},
                       {"robots", robots},
                       {"ground_truth", true},
                       {"images", opt.images},
                       {"render", source.render_device()},
                       {"frames_sha256", external::sha256_hex(frames)}};
  const std::string gz = gzip_compress(frames);
  result.frames_bytes = gz.size();
  result.frames_text_bytes = frames.size();
  dir.write(kFramesFile, gz);
  dir.write("timing.csv", timing);
  dir.write("recording.json", header.dump(2) + "\n");
  dir.commit();
  result.out_dir = dir.final_dir();
  return result;
}

RecordingHeader RecordingHeader::read(const std::string& dir) {
  RecordingHeader h;
  h.dir = dir;
  if (const std::string why = why_not_readable_folder(dir); !why.empty())
    throw ConfigError(path_shown(dir), why, "a recording folder (recording.json, frames.jsonl; docs/recording.md)");
  const std::string file = (fs::path(dir) / "recording.json").string();
  const Json j = read_json_strict(file, file);
  if (!j.is_object()) throw ConfigError(file, json_brief(j), "a recording header object (docs/recording.md)");
  // The format first: a later version's other keys must not be judged by this version's rules.
  const auto fmt = j.find("format");
  if (fmt == j.end() || !fmt->is_string() || fmt->get<std::string>().rfind("omniloc-recording/", 0) != 0)
    throw ConfigError(file + " /format", fmt == j.end() ? "nothing" : json_brief(*fmt), std::string("\"") + kRecordingFormat + "\" (docs/recording.md)");
  if (*fmt != kRecordingFormat)
    throw ConfigError(file + " /format", json_brief(*fmt),
                      std::string("\"") + kRecordingFormat + "\": this omniloc reads version 1 only (a later omniloc wrote this recording)");
  h.format = fmt->get<std::string>();
  JsonReader r(j, file + " ");  // paths read "recording.json /robots/0/id"
  r.allow("format");
  r.allow("comment");
  r.allow("written_by");  // a writer's name (clients/python/omniloc_recording.py)
  if (const Json* o = r.raw("omniloc")) h.omniloc = *o;
  h.name = r.string("name", std::string("recording"));
  h.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0, 1LL << 53));
  if (const Json* s = r.raw("scenario"); s && !s->is_null()) {
    if (!s->is_object()) throw ConfigError(r.child_path("scenario"), json_brief(*s), "the scenario object, or null");
    h.scenario = *s;
  }
  h.scenario_source = r.string("scenario_source", std::string());
  const Json* field = r.raw("field", true);
  if (!field->is_object() && !field->is_string())
    throw ConfigError(r.child_path("field"), json_brief(*field), "a field preset name (omniloc list) or a field object, as a scenario's \"field\"");
  h.field = *field;
  if (const Json* m = r.raw("field_markings")) h.field_markings = *m;
  h.field_fingerprint = r.string("field_fingerprint", std::string());
  // The limits of a scenario's camera_rate and duration (docs/scenario.md): a replay runs one.
  h.camera_rate_hz = r.number("camera_rate_hz", std::nullopt, 1.0, 200.0);
  h.duration_s = r.positive("duration_s", std::nullopt, kMaxTime);
  h.frames = r.integer("frames", std::nullopt, 1, kMaxFrames);
  const Json* robots = r.raw("robots", true);
  if (!robots->is_array() || robots->empty()) throw ConfigError(r.child_path("robots"), json_brief(*robots), "a non-empty array of robots");
  for (std::size_t i = 0; i < robots->size(); ++i) {
    JsonReader rr((*robots)[i], json_child(r.child_path("robots"), i));
    RecordedRobot rob;
    rob.id = static_cast<int>(rr.integer("id", std::nullopt, 0, 1000000));
    if (const Json* st = rr.raw("start"); st && !st->is_null()) rob.start = pose(*st, rr.child_path("start"));
    if (const Json* cam = rr.raw("camera")) {
      if (!cam->is_object()) throw ConfigError(rr.child_path("camera"), json_brief(*cam), "hello.camera's object ({} without a camera)");
      rob.camera = *cam;
    } else {
      rob.camera = Json::object();
    }
    rob.blobs = rr.boolean("blobs", false);
    for (const auto& other : h.robots)
      if (other.id == rob.id) throw ConfigError(rr.child_path("id"), std::to_string(rob.id), "distinct robot ids");
    h.robots.push_back(std::move(rob));
  }
  h.ground_truth = r.boolean("ground_truth", true);
  h.images = r.boolean("images", false);
  if (const Json* rd = r.raw("render")) h.render = *rd;
  h.frames_sha256 = r.string("frames_sha256", std::string());
  h.frames_file = r.string("frames_file", std::string("frames.jsonl"), {"frames.jsonl", "frames.jsonl.gz"});
  // Checked with the header, so a sweep's validation (which reads only headers) refuses a recording
  // whose frames cannot be read (a FIFO would block the reader) before any run.
  const std::string frames = (fs::path(dir) / h.frames_file).string();
  if (const std::string why = why_not_readable_file(frames); !why.empty())
    throw ConfigError(frames, why, "a readable file of the recording (docs/recording.md)");
  // No finish(): keys a later omniloc adds to version 1 are ignored, as docs/recording.md promises.
  return h;
}

std::string recorded_with(const RecordingHeader& h) {
  if (!h.omniloc.is_object()) return "not omniloc";
  const auto v = h.omniloc.find("version");
  return v != h.omniloc.end() && v->is_string() ? v->get<std::string>() : "unknown";
}

RecordingSource::RecordingSource(RecordingHeader header) : header_(std::move(header)), reader_(std::make_unique<FramesReader>(header_)) {
  read_timing();
}

RecordingSource::~RecordingSource() = default;

// timing.csv (optional): the render and vision times the recording's frames cost, for the run's
// timing.csv. A line that does not parse is ignored: these are wall-clock figures, never results.
void RecordingSource::read_timing() {
  // Optional: anything but a readable file (a FIFO would block the read) is as if it were absent.
  const std::string file = (fs::path(header_.dir) / "timing.csv").string();
  if (!why_not_readable_file(file).empty()) return;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return;
  while (std::getline(in, line)) {
    long long k = 0;
    int robot = 0;
    double render = 0, vision = 0;
    if (std::sscanf(line.c_str(), "%lld,%d,%lf,%lf", &k, &robot, &render, &vision) == 4) timing_[{k, robot}] = {render, vision};
  }
}

std::optional<FrameData> RecordingSource::next() {
  std::optional<FrameData> f = reader_->next();
  if (!f) return f;
  for (auto& r : f->robots)
    if (const auto it = timing_.find({f->k, r.id}); it != timing_.end()) std::tie(r.render_ms, r.vision_ms) = it->second;
  if (header_.images) {
    for (auto& r : f->robots) {
      const fs::path p = fs::path(header_.dir) / image_name(r.id, f->k);
      if (const std::string why = why_not_readable_file(p.string()); !why.empty())
        throw ConfigError(p.string(), why, "an image for every frame (recording.json says \"images\": true)");
      r.obs.image = read_png(p.string());
    }
  }
  return f;
}

long long RecordingSource::fast_lines() const { return reader_->fast_lines(); }
long long RecordingSource::strict_lines() const { return reader_->strict_lines(); }

Json RecordingSource::client_camera(int robot) const {
  for (const auto& r : header_.robots)
    if (r.id == robot) return r.camera;
  return Json::object();
}

bool RecordingSource::detects_blobs() const {
  for (const auto& r : header_.robots)
    if (r.blobs) return true;
  return false;
}

// The scenario of a log not made by omniloc: its field, rate, duration and robots (at their start
// poses when given), nothing simulated. A localizer that needs the start pose needs it given.
Json scenario_of_log(const RecordingHeader& h, const LocalizerSpec& localizer) {
  Json robots = Json::array();
  for (const auto& r : h.robots)
    robots.push_back({{"id", r.id}, {"start", r.start ? pose_json(*r.start) : Json::array({0.0, 0.0, 0.0})}, {"localize", true}});
  Json j = {{"field", h.field}, {"camera_rate", h.camera_rate_hz}, {"duration", h.duration_s}, {"noise_profile", "ideal"}, {"robots", robots}};
  if (!localizer.type().empty())
    for (std::size_t i = 0; i < h.robots.size(); ++i)
      if (!h.robots[i].start && localizer_info(localizer).needs_start_pose)
        throw ConfigError(h.dir + "/recording.json /robots/" + std::to_string(i) + "/start", "nothing",
                          "the start pose: " + localizer.type() + " tracks from it");
  return j;
}

Scenario replay_scenario(const RecordingHeader& h, const LocalizerSpec& localizer) {
  Json j = h.scenario.is_null() ? scenario_of_log(h, localizer) : h.scenario;
  j["name"] = h.name;
  j["seed"] = h.seed;
  Scenario sc;
  try {
    sc = parse_scenario(j, h.name, h.scenario_source, &localizer);
  } catch (const LocalizerError&) {
    throw;  // the replay's own input, named where it was given
  } catch (const ConfigError& e) {
    throw ConfigError(h.dir + "/recording.json /scenario" + e.path(), e.value(), e.expected());
  }
  const std::vector<int> ids = sc.localized_robots();
  bool same = ids.size() == h.robots.size();
  for (std::size_t i = 0; same && i < ids.size(); ++i) same = ids[i] == h.robots[i].id;
  if (!same) throw ConfigError(h.dir + "/recording.json /robots", json_brief(Json(ids)), "the scenario's localized robots, in order");
  if (!h.field_fingerprint.empty() && sc.field.fingerprint() != h.field_fingerprint)
    throw ConfigError(h.dir + "/recording.json /field", "a field whose geometry differs from the recorded one",
                      "the recorded field (the preset or field file changed since it was recorded)");
  return sc;
}

}  // namespace omniloc::harness
