#include "harness/scenario.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/json_parse.hpp"
#include "core/params.hpp"
#include "harness/camera_perception.hpp"
#include "harness/vision_setup.hpp"
#include "harness/localizer_registry.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/egl_device.hpp"
#include "sim/motion.hpp"

namespace omniloc::harness {

namespace {

Pose2 read_pose(JsonReader& r, const std::string& key, std::optional<Pose2> def = std::nullopt) {
  std::optional<std::vector<double>> d;
  if (def) d = std::vector<double>{def->x, def->y, def->theta};
  const auto v = r.numbers(key, d, 3);
  return Pose2(v[0], v[1], v[2]);
}

void check_on_floor(const Field& f, const Eigen::Vector2d& p, double clearance, const std::string& path,
                    const std::string& what) {
  if (!f.inside_floor(p, clearance))
    throw ConfigError(path, "[" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + "]",
                      what + " inside the walls (|x| <= " + std::to_string(f.half_floor_x() - clearance) +
                          ", |y| <= " + std::to_string(f.half_floor_y() - clearance) + " m)");
}

// The name becomes a folder under results/runs/: only a safe file-name character set, and never "."
// or "..", which would write beside or above results/runs (or collapse into results/runs/<seed>).
bool safe_name(const std::string& n) {
  if (n.empty() || n.size() > 100 || n == "." || n == "..") return false;
  for (char c : n)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) return false;
  return true;
}

// The file stem as a default name, with characters outside the safe set replaced.
std::string name_from_stem(const std::string& stem) {
  std::string n;
  for (char c : stem) n += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  if (n.size() > 100) n.resize(100);
  return safe_name(n) ? n : std::string("scenario");
}

// A data file named in the scenario must be readable and loadable now, not after the run has
// started writing: its errors are reported at the JSON path that names it.
template <class Load>
void check_data_file(const std::string& file, const std::string& where, const std::string& what, Load load) {
  require_readable_file(file, where, what);
  try {
    load();
  } catch (const std::exception& e) {
    throw ConfigError(where, "\"" + file + "\" (" + e.what() + ")", what);
  }
}

}  // namespace

sim::Lighting Scenario::lighting_at(double t) const {
  sim::Lighting l = lighting;
  for (std::size_t i = 0; i < l.sun.size(); ++i) l.sun[i].centre += sun_velocity[i] * t;
  // Events in time order; each moves its target (the global level, or each listed lamp's state)
  // linearly from where the earlier events left it to the new value over its transition.
  for (const auto& e : events)
    if (const auto* lights = e.as<Lights>(); lights && e.t <= t) lights->shade(l, e.t, t);
  return l;
}

const RobotConfig* Scenario::robot(int id) const {
  for (const auto& r : robots)
    if (r.spec.id == id) return &r;
  return nullptr;
}

std::vector<int> Scenario::localized_robots() const {
  std::vector<int> ids;
  for (const auto& r : robots)
    if (r.localize) ids.push_back(r.spec.id);
  return ids;
}

namespace {

// One element of /robots; `eff` gets the effective values (the profile's noise where not given).
RobotConfig read_robot(const Json& j, std::size_t i, const Scenario& s, std::set<int>& ids, Json& eff) {
  const std::string rp = json_child("/robots", i);
  JsonReader rr(j, rp, &eff);
  rr.allow("comment");
  RobotConfig rc;
  rc.spec.id = static_cast<int>(rr.integer("id", static_cast<long long>(i), 0, 99));
  if (!ids.insert(rc.spec.id).second) throw ConfigError(rp + "/id", std::to_string(rc.spec.id), "a robot id not used by another robot");
  rc.spec.team = static_cast<int>(rr.integer("team", 0, 0, 1));
  rc.spec.start = read_pose(rr, "start");
  rc.spec.radius = rr.number("radius", 0.26, 0.1, 0.4);
  rc.spec.height = rr.number("height", 0.8, 0.2, 1.5);
  rc.spec.max_speed = rr.positive("max_speed", 4.0, 10.0);
  rc.spec.max_accel = rr.positive("max_accel", 3.0, 20.0);
  rc.localize = rr.boolean("localize", i == 0);
  rc.has_heading_sensor = rr.boolean("heading_sensor", true);
  check_on_floor(s.field, rc.spec.start.translation(), rc.spec.radius, rp + "/start", "a start position with the whole robot");
  rc.motion = rr.raw("motion") ? *rr.raw("motion") : Json{{"type", "still"}};
  rc.motion_path = rp + "/motion";
  sim::MotionScript::from_json(rc.motion, rc.motion_path, 0, &s.field);  // validate now
  rc.odometry = s.noise.odometry;
  rc.heading = s.noise.heading;
  if (auto o = rr.object("odometry")) {
    rc.odometry = sim::OdometryNoise::from_json(*o, s.noise.odometry);
    o->finish();
  } else {
    for (const auto& q : sim::OdometryNoise::params()) eff["odometry"][q.key] = param_value(q, rc.odometry);
  }
  if (auto h = rr.object("heading")) {
    rc.heading = sim::HeadingNoise::from_json(*h, s.noise.heading);
    h->finish();
  } else {
    for (const auto& q : sim::HeadingNoise::params()) eff["heading"][q.key] = param_value(q, rc.heading);
  }
  rr.finish();
  return rc;
}

// /robots: each robot, then the checks between robots.
void read_robots(JsonReader& r, Scenario& s) {
  const Json* robots = r.raw("robots", true);
  if (!robots->is_array() || robots->empty())
    throw ConfigError("/robots", json_brief(*robots), "a non-empty array of robot objects");
  std::set<int> ids;
  Json eff_robots = Json::array();
  for (std::size_t i = 0; i < robots->size(); ++i) {
    Json eff;
    s.robots.push_back(read_robot((*robots)[i], i, s, ids, eff));
    eff_robots.push_back(eff);
  }
  s.effective["robots"] = eff_robots;
  // Robots must not start inside one another.
  for (std::size_t a = 0; a < s.robots.size(); ++a)
    for (std::size_t b = a + 1; b < s.robots.size(); ++b) {
      const auto& A = s.robots[a].spec;
      const auto& B = s.robots[b].spec;
      if ((A.start.translation() - B.start.translation()).norm() < A.radius + B.radius)
        throw ConfigError(json_child("/robots", b) + "/start", "robot " + std::to_string(B.id) + " overlapping robot " + std::to_string(A.id),
                          "start positions at least the sum of the radii apart");
    }
  // Behaviours that mark a robot must name another robot of the scenario.
  for (std::size_t i = 0; i < s.robots.size(); ++i) {
    const Json& m = s.robots[i].motion;
    if (m.value("type", "") == "behaviour" && m.value("kind", "") == "mark") {
      const int target = m.value("target", -1);
      if (!s.robot(target) || target == s.robots[i].spec.id)
        throw ConfigError(s.robots[i].motion_path + "/target", std::to_string(target), "the id of another robot in /robots");
    }
  }
  if (s.localized_robots().empty())
    throw ConfigError("/robots", "no robot with \"localize\": true", "at least one localized robot");
}

// /ball: position and velocity.
void read_ball(JsonReader& r, Scenario& s, const Json& j) {
  if (auto b = r.object("ball")) {
    s.has_ball = true;
    const auto p = b->numbers("position", std::nullopt, 2);
    const auto v = b->numbers("velocity", std::vector<double>{0, 0}, 2);
    s.ball_position = {p[0], p[1]};
    s.ball_velocity = {v[0], v[1]};
    // Box2D aborts on a velocity that overflows a float (1e39); the hardest kicks are ~15 m/s.
    if (s.ball_velocity.norm() > 50.0)
      throw ConfigError("/ball/velocity", json_brief(j["ball"]["velocity"]), "a ball velocity of at most 50 m/s");
    check_on_floor(s.field, s.ball_position, 0.11, "/ball/position", "a ball position");
    b->finish();
  }
}

// /events (harness/events.cpp), in time order.
void read_events(JsonReader& r, Scenario& s) {
  if (const Json* ev = r.raw("events")) {
    if (!ev->is_array()) throw ConfigError("/events", json_brief(*ev), "an array of event objects");
    EventContext ctx;
    ctx.field = &s.field;
    ctx.run_duration = s.duration;
    ctx.default_robot = s.localized_robots().front();
    for (const auto& rc : s.robots) ctx.robots.emplace_back(rc.spec.id, rc.spec.radius);
    for (std::size_t i = 0; i < ev->size(); ++i) s.events.push_back(parse_event((*ev)[i], json_child("/events", i), ctx));
    std::stable_sort(s.events.begin(), s.events.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  }
}

// /lighting: level, sun patches, lamps (a list or a grid); then the lamps the events name must exist.
void read_lighting(JsonReader& r, Scenario& s) {
  if (auto l = r.object("lighting")) {
    l->allow("comment");
    s.lighting.level = l->number("level", 1.0, 0.0, 20.0);
    if (const Json* sun = l->raw("sun")) {
      const std::string sp = l->child_path("sun");
      if (!sun->is_array()) throw ConfigError(sp, json_brief(*sun), "an array of sun patches");
      for (std::size_t i = 0; i < sun->size(); ++i) {
        JsonReader pr((*sun)[i], json_child(sp, i));
        pr.allow("comment");
        sim::SunPatch p;
        const bool wall = pr.string("surface", std::string("floor"), {"floor", "wall"}) == "wall";
        p.surface = wall ? sim::SunPatch::Surface::kWall : sim::SunPatch::Surface::kFloor;
        const auto c = pr.numbers("centre", std::nullopt, 2);
        const auto v = pr.numbers("velocity", std::vector<double>{0.0, 0.0}, 2);
        p.centre = {c[0], c[1]};
        if (wall) {
          // A window's light on the hall wall nearest to `centre`: half_width along the wall, height [z0, z1] up it.
          p.half_size = {pr.positive("half_width", 1.0, 100.0), 0.0};
          const auto z = pr.numbers("height", std::vector<double>{0.2, 0.8}, 2);
          if (!(z[0] >= 0 && z[1] > z[0]))
            throw ConfigError(json_child(sp, i) + "/height", json_brief((*sun)[i]["height"]), "[z0, z1] with 0 <= z0 < z1 (metres)");
          p.z_min = z[0];
          p.z_max = z[1];
        } else {
          const auto h = pr.numbers("half_size", std::vector<double>{1.0, 0.5}, 2);
          if (h[0] <= 0 || h[1] <= 0) throw ConfigError(json_child(sp, i) + "/half_size", json_brief((*sun)[i]["half_size"]), "two positive half sizes (metres)");
          p.half_size = {h[0], h[1]};
        }
        p.strength = pr.number("strength", 3.0, 0.0, 50.0);
        pr.finish();
        s.lighting.sun.push_back(p);
        s.sun_velocity.emplace_back(v[0], v[1]);
      }
    }
    // Lamps: an explicit list, or a regular grid of banks over the floor inside the walls.
    if (const Json* lamps = l->raw("lamps")) {
      const std::string lp = l->child_path("lamps");
      if (!lamps->is_array() || lamps->empty()) throw ConfigError(lp, json_brief(*lamps), "a non-empty array of lamps {\"centre\": [x, y], \"spread\": m}");
      for (std::size_t i = 0; i < lamps->size(); ++i) {
        JsonReader lr((*lamps)[i], json_child(lp, i));
        lr.allow("comment");
        sim::Lamp lamp;
        const auto c = lr.numbers("centre", std::nullopt, 2);
        lamp.centre = {c[0], c[1]};
        lamp.spread = lr.positive("spread", 3.0, 100.0);
        lamp.state = lr.number("state", 1.0, 0.0, 20.0);
        lr.finish();
        s.lighting.lamps.push_back(lamp);
      }
    }
    s.lighting.diffuse = l->number("lamp_diffuse", 0.3, 0.0, 1.0);
    if (auto g = l->object("lamp_grid")) {
      if (!s.lighting.lamps.empty()) throw ConfigError(g->path(), "an object", "either /lighting/lamps or /lighting/lamp_grid, not both");
      const int nx = static_cast<int>(g->integer("nx", 4, 1, 50)), ny = static_cast<int>(g->integer("ny", 3, 1, 50));
      const double spread = g->positive("spread", 3.0, 100.0);
      g->finish();
      // Banks at the centres of an nx x ny partition of the floor, numbered row by row from (-x, -y).
      const double hx = s.field.half_floor_x(), hy = s.field.half_floor_y();
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          sim::Lamp lamp;
          lamp.centre = {-hx + (i + 0.5) * 2 * hx / nx, -hy + (j + 0.5) * 2 * hy / ny};
          lamp.spread = spread;
          s.lighting.lamps.push_back(lamp);
        }
    }
    l->finish();
  }
  for (const auto& e : s.events)
    if (const auto* lights = e.as<Lights>())
      for (std::size_t k = 0; k < lights->lamps.size(); ++k)
        if (static_cast<std::size_t>(lights->lamps[k]) >= s.lighting.lamps.size())
          throw ConfigError(json_child(e.path + "/lamps", k), std::to_string(lights->lamps[k]),
                            "the index of a lamp in /lighting/lamps (" + std::to_string(s.lighting.lamps.size()) + " lamps)");
}

// /camera (the profile's defaults under the scenario's values) and /vision, both validated now, data files included.
void read_camera_and_vision(JsonReader& r, Scenario& s) {
  // Camera: the profile's defaults under the scenario's explicit values.
  s.camera = s.noise.camera;
  if (const Json* cam = r.raw("camera")) {
    if (!cam->is_object()) throw ConfigError("/camera", json_brief(*cam), "an object");
    for (auto it = cam->begin(); it != cam->end(); ++it) s.camera[it.key()] = it.value();
  }
  {
    Json eff;
    const auto cam = sim::CameraConfig::from_json(s.camera, "/camera", &eff);  // validate now, record the effective values
    s.effective["camera"] = eff;
    // An "egl" that cannot render on this machine (no device, a device index it lacks) is found
    // now, before any work (exit 2), not at the first frame. "osmesa" is a build dependency.
    if (cam.backend == "egl") {
      const std::string problem = sim::gl_backend_problem("egl");
      if (!problem.empty()) {
        const char* env = std::getenv("OMNILOC_GL_BACKEND");
        throw ConfigError(env && *env ? "$OMNILOC_GL_BACKEND" : "/camera/backend", "\"egl\"",
                          "a GL back-end that can render on this machine (" + problem + ")");
      }
    }
  }
  const Json* vis = r.raw("vision");
  s.vision = vis ? *vis : Json::object();
  {
    Json eff;
    const VisionConfig vc = VisionConfig::from_json(s.vision, "/vision", &eff);
    s.effective["vision"] = eff;
    const auto cam = sim::CameraConfig::from_json(s.camera, "/camera");
    if (vc.calibration != "auto" && vc.calibration != "exact")
      check_data_file(vc.calibration, "/vision/calibration", "\"auto\", \"exact\" or a calibration map file for this camera (omniloc calibrate)",
                      [&] { (void)CalibrationMap::load(vc.calibration, camera_tag(cam), cam.width, cam.height); });
    if (vc.colour_table != "auto")
      check_data_file(vc.colour_table, "/vision/colour_table", "\"auto\" or a colour table file for this field (omniloc colour-calibrate)",
                      [&] { (void)ColourTable::load(vc.colour_table, s.field.fingerprint()); });
  }
}

}  // namespace

Scenario parse_scenario(const Json& j, const std::string& name, const std::string& source, const LocalizerSpec* localizer) {
  Scenario s;
  s.source = source;
  s.input = j;
  // What was run: a replay's or sweep's localizer in place of the scenario's own.
  if (localizer && s.input.is_object()) s.input["localizer"] = localizer->json;
  JsonReader r(j, "", &s.effective);
  r.allow("comment");
  s.name = r.string("name", name_from_stem(name));
  if (!safe_name(s.name))
    throw ConfigError("/name", json_brief(Json(s.name)), "a name of 1 to 100 characters from A-Z a-z 0-9 . _ - (not \".\" or \"..\"); it names the results folder");
  s.description = r.string("description", std::string());
  s.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0, (1LL << 53)));
  s.duration = r.positive("duration", 30.0, 3600.0);
  s.physics_rate = r.number("physics_rate", 200.0, 20.0, 2000.0);
  s.camera_rate = r.number("camera_rate", 30.0, 1.0, 200.0);
  if (s.camera_rate > s.physics_rate)
    throw ConfigError("/camera_rate", std::to_string(s.camera_rate), "a camera rate <= physics_rate (" + std::to_string(s.physics_rate) + " Hz)");

  // Field: a preset name or an inline object.
  const Json* field = r.raw("field");
  if (!field || field->is_string()) {
    s.field = Field::preset(field ? field->get<std::string>() : std::string("msl2012"), "/field");
    s.effective["field"] = s.field.name;
  } else {
    s.field = Field::from_json(*field, "/field");
  }

  s.noise = NoiseProfile::named(r.string("noise_profile", std::string("robot")), "/noise_profile");

  read_robots(r, s);
  read_ball(r, s, j);
  read_events(r, s);
  if (const Json* occ = r.raw("occlusion")) s.occlusion = sim::OcclusionMask::from_json(*occ, "/occlusion");
  read_lighting(r, s);
  const Json* loc = r.raw("localizer");
  if (localizer) {
    s.localizer = *localizer;
  } else if (loc) {
    if (!loc->is_object()) throw ConfigError("/localizer", json_brief(*loc), "an object {\"type\": ...}");
    s.localizer.json = *loc;
    external::anchor_external_paths(s.localizer.json);
  }

  read_camera_and_vision(r, s);
  {
    Json eff = Json::object();
    const Json* sc = r.raw("scoring");
    s.scoring = Scoring::from_json(sc ? *sc : Json::object(), "/scoring", &eff);
    s.effective["scoring"] = eff;
  }
  r.finish();
  validate_deep(s);
  return s;
}

void validate_deep(const Scenario& s) {
  LocalizerContext ctx;
  ctx.field = &s.field;
  ctx.seed = s.seed;
  ctx.camera_latency = declared_camera_latency(s);
  ctx.camera_mount_height = declared_camera_mount_height(s);
  ctx.camera_vibration = declared_camera_vibration(s);
  check_localizer(s.localizer, ctx);
}

Scenario load_scenario(const std::string& path) {
  const Json j = read_json_strict(path, path);
  return parse_scenario(j, std::filesystem::path(path).stem().string(), path);
}

double declared_camera_latency(const Scenario& sc) { return sim::CameraConfig::from_json(sc.camera, "/camera").latency; }
double declared_camera_mount_height(const Scenario& sc) { return sim::CameraConfig::from_json(sc.camera, "/camera").mount_height; }
double declared_camera_vibration(const Scenario& sc) { return sim::CameraConfig::from_json(sc.camera, "/camera").vibration_std; }

}  // namespace omniloc::harness
