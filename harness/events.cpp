#include "harness/events.hpp"

#include <algorithm>
#include <utility>

#include "core/error.hpp"

namespace omniloc::harness {

namespace {

double robot_radius(const EventContext& ctx, int id) {
  for (const auto& [rid, radius] : ctx.robots)
    if (rid == id) return radius;
  return 0.0;
}

// "pose": [x, y, theta] or "random"; a given target must hold the whole robot inside the walls.
template <class K>
void read_target(K& k, JsonReader& r, const std::string& path, int robot, const EventContext& ctx) {
  const Json* pj = r.raw("pose", true);
  if (pj->is_string()) {
    if (pj->get<std::string>() != "random") throw ConfigError(path + "/pose", json_brief(*pj), "[x, y, theta] or \"random\"");
    k.random_pose = true;
    return;
  }
  if (!pj->is_array() || pj->size() != 3 || !(*pj)[0].is_number() || !(*pj)[1].is_number() || !(*pj)[2].is_number())
    throw ConfigError(path + "/pose", json_brief(*pj), "[x, y, theta] or \"random\"");
  k.pose = Pose2((*pj)[0].get<double>(), (*pj)[1].get<double>(), (*pj)[2].get<double>());
  const double clearance = robot_radius(ctx, robot);
  const Field& f = *ctx.field;
  if (!f.inside_floor(k.pose.translation(), clearance))
    throw ConfigError(path + "/pose", "[" + std::to_string(k.pose.x) + ", " + std::to_string(k.pose.y) + "]",
                      "a target with the whole robot inside the walls (|x| <= " + std::to_string(f.half_floor_x() - clearance) +
                          ", |y| <= " + std::to_string(f.half_floor_y() - clearance) + " m)");
}

// --- parse: one function per kind; `raw` is the whole event object ---------------------------------

Teleport parse(std::in_place_type_t<Teleport>, JsonReader& r, const Json&, const std::string& path, int robot, const EventContext& ctx) {
  Teleport k;
  read_target(k, r, path, robot, ctx);
  return k;
}

Kidnap parse(std::in_place_type_t<Kidnap>, JsonReader& r, const Json&, const std::string& path, int robot, const EventContext& ctx) {
  Kidnap k;
  read_target(k, r, path, robot, ctx);
  k.duration = r.positive("duration", 2.0, 3600.0);
  return k;
}

Cover parse(std::in_place_type_t<Cover>, JsonReader& r, const Json&, const std::string&, int, const EventContext&) {
  return Cover{r.positive("duration", 1.0, 3600.0)};
}

Occlude parse(std::in_place_type_t<Occlude>, JsonReader& r, const Json& raw, const std::string& path, int, const EventContext&) {
  Occlude k;
  k.duration = r.positive("duration", 1.0, 3600.0);
  // The mask's keys sit beside the event's own keys.
  Json mask = raw;
  for (const char* key : {"type", "t", "robot", "duration", "comment"}) mask.erase(key);
  k.mask = sim::OcclusionMask::from_json(mask, path);
  for (auto it = mask.begin(); it != mask.end(); ++it) r.allow(it.key());
  return k;
}

Lights parse(std::in_place_type_t<Lights>, JsonReader& r, const Json&, const std::string& path, int, const EventContext&) {
  Lights k;
  k.level = r.number("level", std::nullopt, 0.0, 20.0);
  k.transition = r.number("transition", 0.5, 0.0, 600.0);
  if (const Json* lamps = r.raw("lamps")) {  // indices are checked against /lighting/lamps by the scenario
    if (!lamps->is_array() || lamps->empty()) throw ConfigError(path + "/lamps", json_brief(*lamps), "a non-empty array of lamp indices");
    for (std::size_t i = 0; i < lamps->size(); ++i) {
      const Json& v = (*lamps)[i];
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 10000)
        throw ConfigError(json_child(path + "/lamps", i), json_brief(v), "a lamp index (an integer >= 0)");
      k.lamps.push_back(v.get<int>());
    }
  }
  return k;
}

Slip parse(std::in_place_type_t<Slip>, JsonReader& r, const Json&, const std::string&, int, const EventContext&) {
  Slip k;
  k.duration = r.positive("duration", 1.0, 3600.0);
  k.scale = r.number("scale", 1.5, 0.0, 10.0);
  return k;
}

template <std::size_t... I>
EventKind parse_kind(const std::string& type, JsonReader& r, const Json& raw, const std::string& path, int robot, const EventContext& ctx,
                     std::index_sequence<I...>) {
  EventKind kind;
  const bool found = ((type == std::variant_alternative_t<I, EventKind>::kName
                           ? (kind = parse(std::in_place_type<std::variant_alternative_t<I, EventKind>>, r, raw, path, robot, ctx), true)
                           : false) || ...);
  if (!found) throw ConfigError(path + "/type", "\"" + type + "\"", "an event type");  // unreachable: the reader checked the names
  return kind;
}

template <std::size_t... I>
std::vector<std::string> kind_names(std::index_sequence<I...>) {
  return {std::variant_alternative_t<I, EventKind>::kName...};
}

}  // namespace

void Lights::shade(sim::Lighting& l, double t_event, double t) const {
  const double f = transition > 0 ? std::min(1.0, (t - t_event) / transition) : 1.0;
  if (lamps.empty()) {
    l.level += f * (level - l.level);
  } else {
    for (int k : lamps) l.lamps[static_cast<std::size_t>(k)].state += f * (level - l.lamps[static_cast<std::size_t>(k)].state);
  }
}

std::vector<std::string> event_type_names() { return kind_names(std::make_index_sequence<std::variant_size_v<EventKind>>{}); }

std::string Event::type() const {
  return std::visit([](const auto& k) { return std::string(std::decay_t<decltype(k)>::kName); }, kind);
}

double Event::duration() const {
  if (const auto* k = as<Kidnap>()) return k->duration;
  if (const auto* k = as<Cover>()) return k->duration;
  if (const auto* k = as<Occlude>()) return k->duration;
  if (const auto* k = as<Slip>()) return k->duration;
  return 0.0;
}

Event parse_event(const Json& j, const std::string& path, const EventContext& ctx) {
  JsonReader r(j, path);
  r.allow("comment");
  Event e;
  e.path = path;
  const std::string type = r.string("type", std::nullopt, event_type_names());
  e.t = r.number("t", std::nullopt, 0.0, ctx.run_duration);
  e.robot = static_cast<int>(r.integer("robot", ctx.default_robot, 0, 99));
  if (std::none_of(ctx.robots.begin(), ctx.robots.end(), [&](const auto& rr) { return rr.first == e.robot; }))
    throw ConfigError(path + "/robot", std::to_string(e.robot), "the id of a robot in /robots");
  e.kind = parse_kind(type, r, j, path, e.robot, ctx, std::make_index_sequence<std::variant_size_v<EventKind>>{});
  r.finish();
  return e;
}

}  // namespace omniloc::harness
