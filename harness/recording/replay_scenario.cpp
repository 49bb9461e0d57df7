#include "harness/recording/replay_scenario.hpp"

#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/recording/format/values.hpp"

namespace omniloc::harness {

namespace {

using recording_values::pose_json;

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

}  // namespace

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
