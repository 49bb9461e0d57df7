#include "core/field.hpp"

#include "core/json_parse.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/angles.hpp"
#include "core/install_paths.hpp"

namespace omniloc {

Eigen::Vector2d Goal::left_post() const {
  // Seen from the field, looking towards the goal at +x, "left" is +y.
  const double off = 0.5 * width + 0.5 * post_width;
  return {goal_line_x, side() > 0 ? off : -off};
}
Eigen::Vector2d Goal::right_post() const {
  const double off = 0.5 * width + 0.5 * post_width;
  return {goal_line_x, side() > 0 ? -off : off};
}

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

double distance_to_arc(const Eigen::Vector2d& p, const ArcMarking& arc) {
  const Eigen::Vector2d d = p - arc.centre;
  const double r = d.norm();
  if (arc.sweep >= kTwoPi - 1e-12) return std::fabs(r - arc.radius);
  const double ang = wrap_angle_positive(std::atan2(d.y(), d.x()) - arc.start);
  if (r > 0 && ang <= arc.sweep) return std::fabs(r - arc.radius);
  const Eigen::Vector2d e0 = arc.centre + arc.radius * Eigen::Vector2d(std::cos(arc.start), std::sin(arc.start));
  const double a1 = arc.start + arc.sweep;
  const Eigen::Vector2d e1 = arc.centre + arc.radius * Eigen::Vector2d(std::cos(a1), std::sin(a1));
  return std::min((p - e0).norm(), (p - e1).norm());
}

double Field::distance_to_marking(const Eigen::Vector2d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : segments) best = std::min(best, distance_to_segment(p, s.a, s.b));
  for (const auto& a : arcs) best = std::min(best, distance_to_arc(p, a));
  for (const auto& s : spots) best = std::min(best, std::max(0.0, (p - s.centre).norm() - s.radius));
  return best;
}

bool Field::inside_floor(const Eigen::Vector2d& p, double clearance) const {
  return std::fabs(p.x()) <= half_floor_x() - clearance && std::fabs(p.y()) <= half_floor_y() - clearance;
}

bool Field::has_coloured_objects() const {
  if (!landmarks.empty()) return true;
  for (const auto& g : goals)
    if (g.colour != "white") return true;
  return false;
}

std::string Field::fingerprint() const {
  std::ostringstream os;
  os.precision(9);
  os << name << '|' << length << '|' << width << '|' << line_width << '|' << margin;
  for (const auto& s : segments) os << "|s" << s.a.x() << ',' << s.a.y() << ',' << s.b.x() << ',' << s.b.y();
  for (const auto& a : arcs) os << "|a" << a.centre.x() << ',' << a.centre.y() << ',' << a.radius << ',' << a.start << ',' << a.sweep;
  for (const auto& s : spots) os << "|p" << s.centre.x() << ',' << s.centre.y() << ',' << s.radius;
  // Coloured objects change what a colour table must learn and what landmark localizers use. Only
  // they are hashed (white goals are not), so fields without them keep their fingerprints.
  for (const auto& g : goals)
    if (g.colour != "white") os << "|g" << g.goal_line_x << ',' << g.width << ',' << g.depth << ',' << g.height << ',' << g.post_width << ',' << g.colour;
  for (const auto& l : landmarks)
    os << "|l" << l.id << ',' << l.colour << ',' << l.shape << ',' << l.position.x() << ',' << l.position.y() << ',' << l.size << ',' << l.height;
  // FNV-1a to keep file names short.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : os.str()) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  std::ostringstream hex;
  hex << std::hex << h;
  return hex.str();
}

namespace {

// The standard MSL layout, parameterised by the rule-book dimensions (RoboCup MSL rules 2012).
void add_msl_markings(Field& f, JsonReader& r) {
  const double L = f.length, W = f.width;
  const double hx = 0.5 * L, hy = 0.5 * W;
  const double circle_r = r.positive("centre_circle_radius", 2.0, 4.0);
  const double corner_r = r.number("corner_arc_radius", 0.75, 0.0, 2.0);
  const double pen_mark = r.number("penalty_mark_distance", 3.0, 0.0, 0.5 * L);
  const double spot_r = r.number("spot_radius", 0.075, 0.0, 0.5);
  double pa_depth = 2.25, pa_width = 6.5, ga_depth = 0.75, ga_width = 3.5;
  // "penalty_area": null leaves it out: small fields (e.g. the 2012 humanoid kid-size field of
  // paper 001) have only a goal area, and a made-up penalty area a few decimetres outside it would
  // add parallel lines that alias for a line-matching localizer.
  bool with_pa = true;
  if (r.has("penalty_area") && r.raw("penalty_area")->is_null()) {
    with_pa = false;
  } else if (auto pa = r.object("penalty_area")) {
    pa_depth = pa->positive("depth", 2.25, 0.5 * L);
    pa_width = pa->positive("width", 6.5, W);
    pa->finish();
  }
  if (auto ga = r.object("goal_area")) {
    ga_depth = ga->positive("depth", 0.75, 0.5 * L);
    ga_width = ga->positive("width", 3.5, W);
    ga->finish();
  }
  if (with_pa && (ga_depth >= pa_depth || ga_width >= pa_width))
    throw ConfigError(r.child_path("goal_area"), "goal area " + std::to_string(ga_depth) + " x " + std::to_string(ga_width),
                      "a goal area smaller than the penalty area");
  auto seg = [&](double x0, double y0, double x1, double y1) { f.segments.push_back({{x0, y0}, {x1, y1}}); };
  seg(-hx, -hy, hx, -hy);  // touch lines
  seg(-hx, hy, hx, hy);
  seg(-hx, -hy, -hx, hy);  // goal lines
  seg(hx, -hy, hx, hy);
  seg(0, -hy, 0, hy);      // centre line
  f.arcs.push_back({{0, 0}, circle_r, 0.0, kTwoPi});
  for (int s : {-1, 1}) {
    const double gx = s * hx;
    // Penalty area: two lines out from the goal line and one parallel to it.
    if (with_pa) {
      seg(gx, -0.5 * pa_width, gx - s * pa_depth, -0.5 * pa_width);
      seg(gx, 0.5 * pa_width, gx - s * pa_depth, 0.5 * pa_width);
      seg(gx - s * pa_depth, -0.5 * pa_width, gx - s * pa_depth, 0.5 * pa_width);
    }
    seg(gx, -0.5 * ga_width, gx - s * ga_depth, -0.5 * ga_width);
    seg(gx, 0.5 * ga_width, gx - s * ga_depth, 0.5 * ga_width);
    seg(gx - s * ga_depth, -0.5 * ga_width, gx - s * ga_depth, 0.5 * ga_width);
    if (spot_r > 0) f.spots.push_back({{gx - s * pen_mark, 0.0}, spot_r});
  }
  if (spot_r > 0) f.spots.push_back({{0.0, 0.0}, spot_r});
  if (corner_r > 0) {
    // Quarter circles inside the field at each corner.
    f.arcs.push_back({{-hx, -hy}, corner_r, 0.0, 0.5 * kPi});
    f.arcs.push_back({{hx, -hy}, corner_r, 0.5 * kPi, 0.5 * kPi});
    f.arcs.push_back({{hx, hy}, corner_r, kPi, 0.5 * kPi});
    f.arcs.push_back({{-hx, hy}, corner_r, 1.5 * kPi, 0.5 * kPi});
  }
}

Eigen::Vector2d read_point(JsonReader& r, const std::string& key) {
  auto v = r.numbers(key, std::nullopt, 2);
  return {v[0], v[1]};
}

}  // namespace

Field Field::from_json(const Json& j, const std::string& path) {
  JsonReader r(j, path);
  r.allow("comment");
  Field f;
  f.name = r.string("name", std::string("custom"));
  const std::string type = r.string("type", std::string("msl"), {"msl", "plain"});
  f.length = r.number("length", 18.0, 4.0, 22.0);
  f.width = r.number("width", 12.0, 3.0, 14.0);
  f.line_width = r.number("line_width", 0.125, 0.01, 0.3);
  f.margin = r.number("margin", 1.0, 0.5, 5.0);
  f.wall_height = r.number("wall_height", 0.5, 0.0, 3.0);
  if (type == "msl") {
    add_msl_markings(f, r);
  }
  if (const Json* segs = r.raw("extra_segments")) {
    const std::string sp = r.child_path("extra_segments");
    if (!segs->is_array()) throw ConfigError(sp, json_brief(*segs), "an array of {\"a\": [x, y], \"b\": [x, y]}");
    for (std::size_t i = 0; i < segs->size(); ++i) {
      JsonReader s((*segs)[i], json_child(sp, i));
      f.segments.push_back({read_point(s, "a"), read_point(s, "b")});
      s.finish();
    }
  }
  if (const Json* g = r.raw("goals")) {
    JsonReader gr(*g, r.child_path("goals"));
    Goal proto;
    proto.width = gr.positive("width", 2.0, 5.0);
    proto.depth = gr.positive("depth", 0.6, 2.0);
    proto.height = gr.positive("height", 1.0, 3.0);
    proto.post_width = gr.positive("post_width", 0.125, 0.5);
    const std::vector<std::string> colours = {"white", "yellow", "blue"};
    const std::string c_neg = gr.string("colour_negative_x", std::string("white"), colours);
    const std::string c_pos = gr.string("colour_positive_x", std::string("white"), colours);
    gr.finish();
    Goal a = proto, b = proto;
    a.goal_line_x = -0.5 * f.length;
    a.colour = c_neg;
    b.goal_line_x = 0.5 * f.length;
    b.colour = c_pos;
    f.goals = {a, b};
  }
  if (const Json* lms = r.raw("landmarks")) {
    const std::string lp = r.child_path("landmarks");
    if (!lms->is_array()) throw ConfigError(lp, json_brief(*lms), "an array of landmark objects");
    for (std::size_t i = 0; i < lms->size(); ++i) {
      JsonReader l((*lms)[i], json_child(lp, i));
      Landmark m;
      m.id = l.string("id", "L" + std::to_string(i));
      m.colour = l.string("colour", std::nullopt, {"red", "blue", "yellow", "green", "magenta", "cyan"});
      m.shape = l.string("shape", std::string("cube"), {"cube", "post"});
      m.position = read_point(l, "position");
      m.size = l.positive("size", 0.3, 2.0);
      m.height = l.positive("height", m.size, 3.0);
      l.finish();
      f.landmarks.push_back(m);
    }
  }
  r.finish();
  return f;
}

std::string data_dir() {
  if (const char* env = std::getenv("OMNILOC_DATA_DIR")) return env;
  return (share_dir() / "data").string();
}

std::vector<std::string> Field::preset_names() {
  std::vector<std::string> names;
  const auto dir = std::filesystem::path(data_dir()) / "fields";
  // OMNILOC_DATA_DIR may name anything: an unreadable folder lists no presets rather than throwing.
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".json") names.push_back(it->path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

Field Field::preset(const std::string& name, const std::string& path) {
  const auto file = std::filesystem::path(data_dir()) / "fields" / (name + ".json");
  // A name with a folder part would read any JSON file on the machine as a field (and a FIFO there
  // would block the open): the name is judged before anything is opened.
  const bool plain = !name.empty() && name.find('/') == std::string::npos && name.find('\0') == std::string::npos && name[0] != '.';
  if (!plain || !why_not_readable_file(file.string()).empty()) {
    std::string known;
    for (const auto& n : preset_names()) known += (known.empty() ? "" : ", ") + n;
    throw ConfigError(path, "\"" + path_shown(name) + "\"", "a field preset name (" + known + ")");
  }
  const Json j = read_json_strict(file.string(), path);
  Field f = from_json(j, file.string());
  f.name = name;
  return f;
}

Json Field::markings_json() const {
  Json j{{"name", name}, {"length", length}, {"width", width}, {"margin", margin}, {"line_width", line_width},
         {"segments", Json::array()}, {"arcs", Json::array()}, {"spots", Json::array()}, {"goals", Json::array()}};
  for (const auto& s : segments) j["segments"].push_back({s.a.x(), s.a.y(), s.b.x(), s.b.y()});
  for (const auto& a : arcs) j["arcs"].push_back({a.centre.x(), a.centre.y(), a.radius, a.start, a.sweep});
  for (const auto& s : spots) j["spots"].push_back({s.centre.x(), s.centre.y(), s.radius});
  for (const auto& g : goals) j["goals"].push_back({g.goal_line_x, g.width, g.depth});
  return j;
}

}  // namespace omniloc
