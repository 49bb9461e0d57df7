#include "sim/motion.hpp"

#include <algorithm>
#include <cmath>

namespace omniloc::sim {

namespace {
constexpr double kMaxSpeed = 10.0;  // m/s, the largest max_speed a robot may have
}  // namespace

DriveCommand ConstantScript::command(const WorldState& world, int self, double) {
  DriveCommand c;
  c.omega = omega_;
  if (robot_frame_) {
    const RobotState* r = world.robot(self);
    c.velocity = r ? r->pose.rotation() * velocity_ : velocity_;
  } else {
    c.velocity = velocity_;
  }
  return c;
}

WaypointScript::WaypointScript(std::vector<Eigen::Vector2d> points, double speed, bool loop, Heading heading,
                               double spin_rate, double tolerance)
    : points_(std::move(points)), speed_(speed), loop_(loop), heading_(heading), spin_rate_(spin_rate),
      tolerance_(tolerance) {}

void WaypointScript::on_teleport() {}

DriveCommand WaypointScript::command(const WorldState& world, int self, double) {
  DriveCommand c;
  const RobotState* r = world.robot(self);
  if (!r || next_ >= points_.size()) return c;
  Eigen::Vector2d to = points_[next_] - r->pose.translation();
  if (to.norm() < tolerance_) {
    ++next_;
    if (next_ >= points_.size()) {
      if (!loop_) return c;
      next_ = 0;
    }
    to = points_[next_] - r->pose.translation();
  }
  const double dist = to.norm();
  // Slow down over the last metres so corners are taken without overshoot (a = 2 m/s^2 braking).
  const double v = std::min(speed_, std::sqrt(2.0 * 2.0 * dist));
  c.velocity = dist > 1e-9 ? Eigen::Vector2d(to * (v / dist)) : Eigen::Vector2d::Zero();
  if (heading_ == Heading::Face && dist > 0.05) {
    const double want = std::atan2(to.y(), to.x());
    c.omega = std::clamp(3.0 * angle_diff(want, r->pose.theta), -2.0, 2.0);
  } else if (heading_ == Heading::Spin) {
    c.omega = spin_rate_;
  }
  return c;
}

std::vector<std::string> MotionScript::types() { return {"still", "constant", "waypoints", "behaviour"}; }

std::unique_ptr<MotionScript> MotionScript::from_json(const Json& j, const std::string& path, std::uint64_t seed,
                                                     const Field* field) {
  JsonReader r(j, path);
  r.allow("comment");
  const std::string type = r.string("type", std::nullopt, types());
  std::unique_ptr<MotionScript> out;
  if (type == "still") {
    out = std::make_unique<StillScript>();
  } else if (type == "constant") {
    const auto v = r.numbers("velocity", std::vector<double>{0.0, 0.0}, 2);
    // Box2D aborts on a velocity that is not finite in float (1e39); the drive clamps to max_speed
    // anyway, so anything beyond the fastest robot allowed (10 m/s) is a typo.
    for (std::size_t k = 0; k < 2; ++k)
      if (std::fabs(v[k]) > kMaxSpeed)
        throw ConfigError(json_child(r.child_path("velocity"), k), json_brief(j["velocity"][k]), "a speed in [-10, 10] m/s");
    const double omega = r.number("omega", 0.0, -20.0, 20.0);
    const std::string frame = r.string("frame", std::string("world"), {"world", "robot"});
    out = std::make_unique<ConstantScript>(Eigen::Vector2d(v[0], v[1]), omega, frame == "robot");
  } else if (type == "behaviour") {
    BehaviourParams p;
    p.kind = r.string("kind", std::nullopt, {"chase_ball", "mark", "hold", "wander"});
    p.speed = r.positive("speed", 2.0, 6.0);
    p.attack_side = r.integer("attack_side", 1, -1, 1) >= 0 ? 1 : -1;
    if (p.kind == "mark") p.target_robot = static_cast<int>(r.integer("target", std::nullopt, 0, 99));
    if (p.kind == "hold") {
      const auto h = r.numbers("home", std::nullopt, 2);
      if (std::fabs(h[0]) > 100 || std::fabs(h[1]) > 100)
        throw ConfigError(r.child_path("home"), json_brief(j["home"]), "a point within 100 m of the centre spot");
      p.home = {h[0], h[1]};
      p.radius = r.number("radius", 0.5, 0.0, 5.0);
    }
    if (field) {
      p.field_half_x = 0.5 * field->length;
      p.field_half_y = 0.5 * field->width;
    }
    out = std::make_unique<BehaviourScript>(p, Rng(seed));
  } else {
    const Json* pts = r.raw("points", true);
    const std::string pp = r.child_path("points");
    if (!pts->is_array() || pts->size() < 1) throw ConfigError(pp, json_brief(*pts), "an array of [x, y] points (metres)");
    std::vector<Eigen::Vector2d> points;
    for (std::size_t i = 0; i < pts->size(); ++i) {
      const Json& p = (*pts)[i];
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
        throw ConfigError(json_child(pp, i), json_brief(p), "a point [x, y] in metres");
      points.emplace_back(p[0].get<double>(), p[1].get<double>());
      // A waypoint beyond the walls can never be reached (the robot pushes against the wall for
      // ever); without a field (unit tests) the largest field's floor bounds it.
      const double hx = field ? field->half_floor_x() : 12.0, hy = field ? field->half_floor_y() : 8.0;
      if (!(std::fabs(points.back().x()) <= hx && std::fabs(points.back().y()) <= hy))
        throw ConfigError(json_child(pp, i), json_brief(p),
                          "a point on the floor inside the walls (|x| <= " + std::to_string(hx) + ", |y| <= " + std::to_string(hy) + " m)");
    }
    const double speed = r.positive("speed", 1.0, 6.0);
    const bool loop = r.boolean("loop", false);
    const std::string heading = r.string("heading", std::string("keep"), {"keep", "face", "spin"});
    const double spin = r.number("spin_rate", 0.5, -20.0, 20.0);
    const double tol = r.positive("tolerance", 0.05, 2.0);
    const auto h = heading == "keep" ? WaypointScript::Heading::Keep
                   : heading == "face" ? WaypointScript::Heading::Face
                                       : WaypointScript::Heading::Spin;
    out = std::make_unique<WaypointScript>(std::move(points), speed, loop, h, spin, tol);
  }
  r.finish();
  return out;
}

}  // namespace omniloc::sim
