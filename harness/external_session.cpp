#include "harness/external_session.hpp"

#include "core/version.hpp"
#include "harness/localizer_registry.hpp"

namespace omniloc::harness {

Json field_for_client(const Field& field) {
  Json j = field.markings_json();
  j["goal_colours"] = Json::array();
  for (const auto& g : field.goals) j["goal_colours"].push_back(g.colour);
  j["landmarks"] = Json::array();
  for (const auto& l : field.landmarks)
    j["landmarks"].push_back({{"colour", l.colour}, {"shape", l.shape}, {"position", {l.position.x(), l.position.y()}}, {"size", l.size}, {"height", l.height}});
  return j;
}

Json camera_for_client(const CalibrationMap* map) {
  if (!map) return Json::object();
  const auto& radii = map->radii_px();
  Json bearings = Json::array();
  for (std::size_t i = 0; i < radii.size(); ++i) bearings.push_back(kTwoPi * static_cast<double>(i) / static_cast<double>(radii.size()));
  return {{"width", map->image_width()},
          {"height", map->image_height()},
          {"channels", 3},
          {"layout", "HWC"},
          {"mirror_centre_px", {map->centre().x(), map->centre().y()}},
          {"calibration",
           {{"bearings_rad", bearings},
            {"radii_px", radii},
            {"distances_m", map->distances_m()},
            {"min_radius_px", map->min_radius()},
            {"max_radius_px", map->max_radius()}}}};
}

external::Session make_session(const Scenario& sc, int robot, const Json& camera, bool blobs, std::uint64_t localizer_seed,
                               const std::string& log_dir) {
  external::Session s;
  s.robot = robot;
  s.scenario = sc.name;
  s.omniloc_version = build_info_json().value("version", std::string("unknown"));
  s.camera_rate_hz = sc.camera_rate;
  s.duration_s = sc.duration;
  s.field = field_for_client(sc.field);
  s.camera = camera;
  // Added to olp/1 after its first version (a field old clients ignore); a recording's header keeps
  // hello.camera without it, and a replay takes it from the recorded scenario, as built-in
  // localizers do (LocalizerContext::camera_latency).
  s.camera["latency_s"] = declared_camera_latency(sc);
  s.camera["mount_height_m"] = declared_camera_mount_height(sc);
  s.camera["vibration_rad"] = declared_camera_vibration(sc);
  s.blobs = blobs;
  s.log_dir = log_dir;
  s.seed = localizer_seed;
  for (const auto& l : localizers())
    if (l.type != "external") s.reserved_names.push_back(l.type);
  return s;
}

}  // namespace omniloc::harness
