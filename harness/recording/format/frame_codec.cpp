#include "harness/recording/format/frame_codec.hpp"

#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "external/external_localizer.hpp"
#include "harness/recording/format/limits.hpp"
#include "harness/recording/format/values.hpp"

namespace omniloc::harness {

namespace {

using namespace recording_limits;  // docs/recording.md section 7
using namespace recording_values;

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

}  // namespace omniloc::harness
