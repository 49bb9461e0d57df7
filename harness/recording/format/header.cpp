#include "harness/recording/format/header.hpp"

#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/recording/format/limits.hpp"
#include "harness/recording/format/values.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;
using namespace recording_limits;  // docs/recording.md section 7
using recording_values::pose;

std::string image_name(int robot, long long k) {
  char name[64];
  std::snprintf(name, sizeof name, "images/r%d_%06lld.png", robot, k);
  return name;
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

}  // namespace omniloc::harness
