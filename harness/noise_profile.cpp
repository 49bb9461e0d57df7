#include <algorithm>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

namespace {

// data/noise_profiles.json, read once per process: the profiles in file order.
const std::vector<NoiseProfile>& profiles() {
  static const std::vector<NoiseProfile> list = [] {
    const std::string file = data_dir() + "/noise_profiles.json";
    const Json j = read_json_strict(file, file);
    JsonReader top(j, "");
    top.allow("comment");
    const Json* arr = top.raw("profiles", true);
    top.finish();
    if (!arr->is_array() || arr->empty()) throw ConfigError(file + ": /profiles", json_brief(*arr), "a non-empty array of noise profiles");
    std::vector<NoiseProfile> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const std::string path = json_child("/profiles", i);
      JsonReader r((*arr)[i], path);
      r.allow("comment");
      r.allow("description");
      NoiseProfile p;
      p.name = r.string("name", std::nullopt);
      if (const Json* base = r.raw("extends")) {
        const auto it = std::find_if(out.begin(), out.end(), [&](const NoiseProfile& q) { return base->is_string() && q.name == base->get<std::string>(); });
        if (it == out.end()) throw ConfigError(file + ": " + path + "/extends", json_brief(*base), "the name of a profile listed before this one");
        const std::string name = p.name;
        p = *it;
        p.name = name;
      }
      if (auto o = r.object("odometry")) {
        o->allow("comment");
        p.odometry = sim::OdometryNoise::from_json(*o, p.odometry);
        o->finish();
      }
      if (auto h = r.object("heading")) {
        h->allow("comment");
        p.heading = sim::HeadingNoise::from_json(*h, p.heading);
        h->finish();
      }
      if (const Json* cam = r.raw("camera")) {
        if (!cam->is_object()) throw ConfigError(file + ": " + path + "/camera", json_brief(*cam), "an object of camera keys");
        if (p.camera.is_null()) p.camera = Json::object();
        for (auto it = cam->begin(); it != cam->end(); ++it) p.camera[it.key()] = it.value();
      }
      r.finish();
      out.push_back(p);
    }
    return out;
  }();
  return list;
}

}  // namespace

std::vector<std::string> NoiseProfile::names() {
  std::vector<std::string> n;
  for (const auto& p : profiles()) n.push_back(p.name);
  return n;
}

NoiseProfile NoiseProfile::named(const std::string& name, const std::string& path) {
  for (const auto& p : profiles())
    if (p.name == name) return p;
  std::string expected = "a noise profile (data/noise_profiles.json):";
  for (const auto& n : names()) expected += " \"" + n + "\"";
  throw ConfigError(path, "\"" + name + "\"", expected);
}

}  // namespace omniloc::harness
