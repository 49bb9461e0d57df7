#include "harness/scenario_schema.hpp"

#include <cstdio>

#include "core/field.hpp"
#include "core/params.hpp"
#include "harness/events.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/scenario.hpp"
#include "localization/vision/blobs.hpp"
#include "localization/vision/exposure_control.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/motion.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/render/mirror.hpp"
#include "sim/sensors.hpp"

namespace omniloc::harness {

namespace {

const Json kComment = {{"type", "string"}, {"description", "free text, ignored"}};

Json object_of(Json properties, const std::string& description = "", bool closed = true) {
  properties["comment"] = kComment;
  Json o{{"type", "object"}, {"properties", properties}};
  if (!description.empty()) o["description"] = description;
  if (closed) o["additionalProperties"] = false;
  return o;
}

Json number(const std::string& description) { return {{"type", "number"}, {"description", description}}; }
Json numbers(std::size_t n, const std::string& description) {
  return {{"type", "array"}, {"items", {{"type", "number"}}}, {"minItems", n}, {"maxItems", n}, {"description", description}};
}
Json one_of_strings(const std::vector<std::string>& names, const std::string& description) {
  return {{"type", "string"}, {"enum", names}, {"description", description}};
}

// Camera keys with their types and the defaults a scenario gets (what from_json records for an empty
// object; docs/camera.md says what each means, from_json checks ranges and cross-field rules).
Json camera_schema() {
  Json props = Json::object();
  Json defaults;
  sim::CameraConfig::from_json(Json::object(), "/camera", &defaults);
  for (const auto& [key, value] : defaults.items()) {
    Json s{{"default", value}};
    s["type"] = value.is_boolean() ? "boolean" : value.is_number_integer() ? "integer" : value.is_number() ? "number" : value.is_string() ? "string" : "array";
    props[key] = s;
  }
  props["mirror"]["enum"] = sim::MirrorProfile::presets();
  props["backend"]["enum"] = sim::gl_backends();
  props["quality"]["enum"] = {"low", "default", "high"};
  return object_of(props, "the simulated camera (docs/camera.md); the noise profile's values under these");
}

Json vision_schema() {
  Json blobs = params_schema(BlobParams::params());
  blobs["detect"] = one_of_strings({"auto", "on", "off"}, "auto: when the field has coloured goals or landmarks");
  const Json colours = {{"type", "array"}, {"items", {{"type", "string"}, {"enum", {"yellow", "blue", "red"}}}}};
  blobs["colours"] = colours;
  blobs["colours"]["description"] = "colour classes searched for";
  blobs["edge_colours"] = colours;
  blobs["edge_colours"]["description"] = "colours whose regions also give edge observations (default: the field's coloured goals)";
  return object_of({{"calibration", {{"type", "string"}, {"description", "\"auto\" (cached model-free calibration), \"exact\", or a map file"}}},
                    {"colour_table", {{"type", "string"}, {"description", "\"auto\" (cached, learned) or a table file"}}},
                    {"scan_lines", object_of(params_schema(ScanLineParams::params()), "radial scan lines (paper 002)")},
                    {"exposure_control", object_of(params_schema(ExposureParams::params()), "entropy auto-adjustment (paper 002)")},
                    {"blobs", object_of(blobs, "coloured-blob detection (papers 003 / 004)")}},
                   "the vision front end");
}

Json localizer_schema() {
  std::vector<std::string> types;
  Json cases = Json::array();
  for (const auto& l : localizers()) {
    types.push_back(l.type);
    Json props = l.schema();
    props["type"] = {{"const", l.type}};
    props["comment"] = kComment;
    Json then{{"properties", props}, {"additionalProperties", false}, {"description", l.description}};
    if (l.type == "external") then["required"] = {"command"};  // the client program (docs/protocol.md)
    cases.push_back({{"if", {{"properties", {{"type", {{"const", l.type}}}}}}}, {"then", then}});
  }
  return {{"type", "object"},
          {"description", "the localizer and its parameters (docs/localizers.md)"},
          {"properties", {{"type", one_of_strings(types, "the localizer (omniloc list)")}}},
          {"required", {"type"}},
          {"allOf", cases}};
}

Json robot_schema() {
  return object_of(
      {{"id", {{"type", "integer"}, {"minimum", 0}, {"maximum", 99}}},
       {"team", {{"type", "integer"}, {"minimum", 0}, {"maximum", 1}}},
       {"start", numbers(3, "[x, y, theta]: metres, radians, world frame")},
       {"radius", number("metres (0.26)")},
       {"height", number("metres (0.8)")},
       {"max_speed", number("m/s (4)")},
       {"max_accel", number("m/s^2 (3)")},
       {"localize", {{"type", "boolean"}, {"description", "run the localizer on this robot and score it (default: the first robot)"}}},
       {"heading_sensor", {{"type", "boolean"}, {"description", "a compass / MTi (default true)"}}},
       {"motion", object_of({{"type", one_of_strings(sim::MotionScript::types(), "motion script (docs/scenario.md)")}}, "the robot's motion script", false)},
       {"odometry", object_of(params_schema(sim::OdometryNoise::params()), "odometry noise (default: the noise profile's)")},
       {"heading", object_of(params_schema(sim::HeadingNoise::params()), "heading-sensor noise (default: the noise profile's)")}},
      "a robot");
}

Json event_schema() {
  // Every kind's keys in one object (an editor completes them); the reader checks each kind's own.
  return object_of({{"type", one_of_strings(event_type_names(), "the event kind (docs/scenario.md, Events)")},
                    {"t", number("seconds")},
                    {"robot", {{"type", "integer"}, {"description", "default: the first localized robot"}}},
                    {"pose", {{"description", "teleport / kidnap: [x, y, theta] or \"random\""}}},
                    {"duration", number("cover / kidnap / occlude / slip: seconds")},
                    {"level", number("lights: the new level or lamp state")},
                    {"transition", number("lights: seconds to reach it")},
                    {"lamps", {{"type", "array"}, {"items", {{"type", "integer"}}}, {"description", "lights: indices into /lighting/lamps"}}},
                    {"scale", number("slip: odometry / wheel motion")},
                    {"fraction", number("occlude: fraction of the panorama")},
                    {"sectors", {{"description", "occlude: a count, or [[start_deg, width_deg], ...]"}}},
                    {"start_deg", number("occlude: first sector's start")},
                    {"frame", one_of_strings({"robot", "world"}, "occlude: sectors fixed to the robot or the world")}},
                   "a scripted event");
}

Json lighting_schema() {
  const Json sun = object_of({{"surface", one_of_strings({"floor", "wall"}, "")},
                              {"centre", numbers(2, "metres")},
                              {"velocity", numbers(2, "m/s")},
                              {"half_size", numbers(2, "floor beam: metres")},
                              {"half_width", number("wall patch: metres along the wall")},
                              {"height", numbers(2, "wall patch: [z0, z1] metres")},
                              {"strength", number("in units of the normal level")}});
  const Json lamp = object_of({{"centre", numbers(2, "metres")}, {"spread", number("metres")}, {"state", number("0 off, 1 on")}});
  return object_of({{"level", number("the lamps' global level (1 = normal)")},
                    {"sun", {{"type", "array"}, {"items", sun}}},
                    {"lamps", {{"type", "array"}, {"items", lamp}}},
                    {"lamp_grid", object_of({{"nx", {{"type", "integer"}}}, {"ny", {{"type", "integer"}}}, {"spread", number("metres")}})},
                    {"lamp_diffuse", number("share of the light that is diffuse")}},
                   "illumination (docs/scenario.md, Lighting)");
}

}  // namespace

Json scenario_schema() {
  Json field_names = Field::preset_names();
  Json props = {
      {"name", {{"type", "string"}, {"description", "names the results folder (default: the file's stem)"}}},
      {"description", {{"type", "string"}}},
      {"seed", {{"type", "integer"}, {"minimum", 0}}},
      {"duration", number("seconds (30)")},
      {"physics_rate", number("Hz (200)")},
      {"camera_rate", number("Hz (30)")},
      {"field", {{"description", "a preset name or a field object (docs/scenario.md)"},
                 {"anyOf", {{{"type", "string"}, {"enum", field_names}}, {{"type", "object"}}}}}},
      {"noise_profile", one_of_strings(NoiseProfile::names(), "sensor-noise defaults (data/noise_profiles.json)")},
      {"robots", {{"type", "array"}, {"minItems", 1}, {"items", robot_schema()}}},
      {"ball", object_of({{"position", numbers(2, "metres")}, {"velocity", numbers(2, "m/s")}})},
      {"events", {{"type", "array"}, {"items", event_schema()}}},
      {"occlusion", object_of({{"fraction", number("")}, {"sectors", Json::object()}, {"start_deg", number("")}, {"frame", one_of_strings({"robot", "world"}, "")}},
                              "black sectors for the whole run")},
      {"lighting", lighting_schema()},
      {"localizer", localizer_schema()},
      {"camera", camera_schema()},
      {"vision", vision_schema()},
      {"scoring", object_of({{"recall", {{"type", "array"},
                                          {"minItems", 1},
                                          {"maxItems", 8},
                                          {"items", object_of({{"position_m", number("metres (> 0, <= 50)")}, {"heading_deg", number("degrees (> 0, <= 180)")}},
                                                              "a frame within both counts as localized")}}}},
                            "recall thresholds (docs/results.md); default 10 cm / 5 deg, 25 cm / 10 deg, 50 cm / 20 deg")},
  };
  Json s = object_of(props, "an omniloc scenario (docs/scenario.md)");
  s["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  s["title"] = "omniloc scenario";
  s["required"] = {"robots"};
  return s;
}

namespace {

std::string cell(const Json& v) {
  if (v.is_number_float()) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v.get<double>());
    return b;
  }
  return v.is_null() ? "" : v.dump();
}

std::string range(const Json& s) {
  if (s.contains("enum")) {
    std::string r;
    for (const auto& e : s["enum"]) r += (r.empty() ? "" : ", ") + e.get<std::string>();
    return r;
  }
  const std::string lo = s.contains("exclusiveMinimum") ? "> " + cell(s["exclusiveMinimum"]) : s.contains("minimum") ? cell(s["minimum"]) : "";
  const std::string hi = s.contains("maximum") ? cell(s["maximum"]) : "";
  if (lo.empty() && hi.empty()) return s.value("type", "");
  if (s.contains("exclusiveMinimum")) return lo + ", <= " + hi;
  return lo + " .. " + hi;
}

// One table of an object's properties; nested objects become their own sections below it.
void table(const std::string& title, const std::string& intro, const Json& props, std::string& md) {
  md += "\n### " + title + "\n";
  if (!intro.empty()) md += intro + "\n";
  std::string rows, nested;
  for (const auto& [key, s] : props.items()) {
    if (key == "comment" || key == "type") continue;
    if (s.value("type", "") == "object" && s.contains("properties")) {
      table(title + " / " + key, s.value("description", ""), s["properties"], nested);
      continue;
    }
    rows += "| `" + key + "` | " + cell(s.value("default", Json())) + " | " + range(s) + " | " + s.value("description", "") + " |\n";
  }
  if (!rows.empty()) md += "\n| key | default | range | meaning [unit] |\n|---|---|---|---|\n" + rows;
  md += nested;
}

}  // namespace

std::string parameter_reference() {
  std::string md =
      "# Parameter reference\n\n"
      "Generated by `omniloc schema --markdown` from the parameter lists in the code (core/params.hpp);\n"
      "ctest `parameter_reference` fails when this page and the code disagree. Every key is optional;\n"
      "config.json of a run records every value it used, defaults included. `omniloc schema` prints\n"
      "the JSON Schema of scenario files for an editor (e.g. VS Code's `json.schemas` setting).\n\n"
      "## Localizers\n"
      "Scenario key `localizer`: `{\"type\": NAME, ...parameters}`. How far each built-in one is from\n"
      "the accuracy limit on the same frames (its efficiency, RMSE / Cramér–Rao bound): docs/results.md,\n"
      "\"Each built-in localizer against the limit\".\n";
  for (const auto& l : localizers()) table("`" + l.type + "`", l.description + ".", l.schema(), md);
  md += "\n## Vision front end\nScenario key `vision`.\n";
  const Json vision = scenario_schema()["properties"]["vision"]["properties"];
  for (const char* k : {"scan_lines", "exposure_control", "blobs"})
    table(std::string("`vision/") + k + "`", vision[k].value("description", ""), vision[k]["properties"], md);
  md += "\n## Sensor noise\nA robot's `odometry` and `heading` objects; the noise profile gives the defaults.\n";
  table("`odometry`", "", params_schema(sim::OdometryNoise::params()), md);
  table("`heading`", "", params_schema(sim::HeadingNoise::params()), md);
  md += "\n## Noise profiles\nFrom `data/noise_profiles.json` (the argument for each value is there):\n\n"
        "| profile | odometry | heading | camera |\n|---|---|---|---|\n";
  for (const auto& name : NoiseProfile::names()) {
    const NoiseProfile p = NoiseProfile::named(name, "");
    char odo[160], head[160];
    std::snprintf(odo, sizeof odo, "trans %g m/sqrt(m), rot %g rad/sqrt(rad), %g rad/sqrt(m), scale %g", p.odometry.trans_sigma, p.odometry.rot_sigma,
                  p.odometry.rot_per_trans, p.odometry.scale_sigma);
    std::snprintf(head, sizeof head, "white %.4g rad, bias walk %.4g rad/sqrt(s)", p.heading.noise_sigma, p.heading.bias_walk);
    md += "| `" + name + "` | " + odo + " | " + head + " | `" + (p.camera.is_null() ? std::string("{}") : p.camera.dump()) + "` |\n";
  }
  return md;
}

}  // namespace omniloc::harness
