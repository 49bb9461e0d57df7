#include "sim/world.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.hpp"

namespace omniloc::sim {

struct World::Robot {
  RobotSpec spec;
  b2Body* body = nullptr;
  Eigen::Vector2d wheel_velocity = Eigen::Vector2d::Zero();  // world frame, what the drive does
  double wheel_omega = 0.0;
  Eigen::Vector2d drive_accel = Eigen::Vector2d::Zero();  // world frame, m/s^2, over the last step
  DriveCommand cmd;
  Pose2 last_wheel_motion;
  bool contact = false;
};

namespace {
b2Vec2 v2(const Eigen::Vector2d& v) { return b2Vec2(static_cast<float>(v.x()), static_cast<float>(v.y())); }

// Moves `current` towards `target` by at most max_step (vector rate limit).
Eigen::Vector2d approach(const Eigen::Vector2d& current, const Eigen::Vector2d& target, double max_step) {
  const Eigen::Vector2d d = target - current;
  const double n = d.norm();
  return n <= max_step ? target : Eigen::Vector2d(current + d * (max_step / n));
}
}  // namespace

World::World(const Field& field, double rate_hz)
    : field_(field), rate_(rate_hz), dt_(1.0 / rate_hz), world_(std::make_unique<b2World>(b2Vec2(0, 0))) {
  if (!(rate_hz >= 10.0 && rate_hz < 1e9)) throw ConfigError("/physics_rate", std::to_string(rate_hz), "a physics rate of at least 10 Hz (a step of at most 0.1 s)");
  build_static_geometry();
}

World::~World() = default;

void World::build_static_geometry() {
  b2BodyDef def;
  b2Body* ground = world_->CreateBody(&def);
  // Two-sided edges: Box2D 2.4 chain shapes collide on one side only.
  auto edge = [&](double x0, double y0, double x1, double y1) {
    b2EdgeShape e;
    e.SetTwoSided(b2Vec2(static_cast<float>(x0), static_cast<float>(y0)), b2Vec2(static_cast<float>(x1), static_cast<float>(y1)));
    b2FixtureDef fd;
    fd.shape = &e;
    fd.friction = 0.3f;
    fd.restitution = 0.3f;
    ground->CreateFixture(&fd);
  };
  const double hx = field_.half_floor_x(), hy = field_.half_floor_y();
  edge(-hx, -hy, hx, -hy);
  edge(hx, -hy, hx, hy);
  edge(hx, hy, -hx, hy);
  edge(-hx, hy, -hx, -hy);
  // Goals: posts and the net's sides and back are obstacles too.
  for (const auto& g : field_.goals) {
    const double s = g.side();
    const double hp = 0.5 * g.post_width;
    for (const Eigen::Vector2d& post : {g.left_post(), g.right_post()}) {
      b2PolygonShape box;
      box.SetAsBox(static_cast<float>(hp), static_cast<float>(hp), v2(post), 0.0f);
      ground->CreateFixture(&box, 0.0f);
    }
    const double x0 = g.goal_line_x + s * hp, x1 = g.goal_line_x + s * g.depth;
    const double yw = 0.5 * g.width + g.post_width;
    edge(x0, -yw, x1, -yw);
    edge(x1, -yw, x1, yw);
    edge(x1, yw, x0, yw);
  }
}

void World::add_robot(const RobotSpec& spec) {
  for (const auto& r : robots_)
    if (r->spec.id == spec.id) throw std::invalid_argument("duplicate robot id " + std::to_string(spec.id));
  auto r = std::make_unique<Robot>();
  r->spec = spec;
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position = v2(spec.start.translation());
  def.angle = static_cast<float>(spec.start.theta);
  def.bullet = true;
  r->body = world_->CreateBody(&def);
  b2CircleShape shape;
  shape.m_radius = static_cast<float>(spec.radius);
  b2FixtureDef fd;
  fd.shape = &shape;
  fd.density = static_cast<float>(spec.mass / (kPi * spec.radius * spec.radius));
  fd.friction = 0.1f;  // hard plastic bumpers: little tangential grip, so bumps push more than they spin
  fd.restitution = 0.1f;
  r->body->CreateFixture(&fd);
  specs_.push_back(spec);
  robots_.push_back(std::move(r));
}

void World::set_ball(const Eigen::Vector2d& position, const Eigen::Vector2d& velocity) {
  remove_ball();
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position = v2(position);
  def.linearVelocity = v2(velocity);
  def.linearDamping = 0.4f;  // rolling resistance on carpet: a kicked ball slows over a few metres
  def.angularDamping = 1.0f;
  def.bullet = true;
  ball_ = world_->CreateBody(&def);
  b2CircleShape shape;
  shape.m_radius = static_cast<float>(ball_radius_);
  b2FixtureDef fd;
  fd.shape = &shape;
  fd.density = static_cast<float>(0.45 / (kPi * ball_radius_ * ball_radius_));  // ~0.45 kg size-5 ball
  fd.restitution = 0.6f;
  fd.friction = 0.2f;
  ball_->CreateFixture(&fd);
}

void World::remove_ball() {
  if (ball_) world_->DestroyBody(ball_);
  ball_ = nullptr;
}

World::Robot& World::robot(int id) {
  for (auto& r : robots_)
    if (r->spec.id == id) return *r;
  throw std::out_of_range("no robot with id " + std::to_string(id));
}
const World::Robot& World::robot(int id) const { return const_cast<World*>(this)->robot(id); }

void World::command(int robot_id, const DriveCommand& cmd) { robot(robot_id).cmd = cmd; }

void World::teleport(int robot_id, const Pose2& pose) {
  Robot& r = robot(robot_id);
  r.body->SetTransform(v2(pose.translation()), static_cast<float>(pose.theta));
  r.body->SetLinearVelocity(b2Vec2(0, 0));
  r.body->SetAngularVelocity(0);
  r.wheel_velocity.setZero();
  r.wheel_omega = 0.0;
  r.drive_accel.setZero();
}

void World::step() {
  for (auto& r : robots_) {
    const RobotSpec& s = r->spec;
    Eigen::Vector2d v = r->cmd.velocity;
    if (v.norm() > s.max_speed) v *= s.max_speed / v.norm();
    const double w = std::clamp(r->cmd.omega, -s.max_omega, s.max_omega);
    const Eigen::Vector2d before = r->wheel_velocity;
    r->wheel_velocity = approach(r->wheel_velocity, v, s.max_accel * dt_);
    r->drive_accel = (r->wheel_velocity - before) / dt_;
    r->wheel_omega += std::clamp(w - r->wheel_omega, -s.max_alpha * dt_, s.max_alpha * dt_);
    // The drive imposes its velocity on the body; contacts then act within the step, so a robot
    // stopped by a wall or pushed by another ends up where its wheels did not take it.
    r->body->SetLinearVelocity(v2(r->wheel_velocity));
    r->body->SetAngularVelocity(static_cast<float>(r->wheel_omega));
    // Wheel motion over this step in the robot frame at the step start (the drive velocity is held
    // constant in the world frame during the step, so this is exact).
    const Eigen::Vector2d local_start = Pose2(0, 0, r->body->GetAngle()).inverse_transform(r->wheel_velocity * dt_);
    r->last_wheel_motion = Pose2(local_start.x(), local_start.y(), r->wheel_omega * dt_);
  }
  world_->Step(static_cast<float>(dt_), 8, 3);
  ++steps_;
  for (auto& r : robots_) {
    bool touching = false;
    for (b2ContactEdge* ce = r->body->GetContactList(); ce; ce = ce->next)
      touching = touching || ce->contact->IsTouching();
    r->contact = touching;
  }
}

Pose2 World::pose(int robot_id) const {
  const b2Body* b = robot(robot_id).body;
  return Pose2(b->GetPosition().x, b->GetPosition().y, b->GetAngle());
}

Pose2 World::wheel_motion(int robot_id) const { return robot(robot_id).last_wheel_motion; }
bool World::in_contact(int robot_id) const { return robot(robot_id).contact; }

WorldState World::state() const {
  WorldState s;
  s.t = time();
  for (const auto& r : robots_) {
    RobotState rs;
    rs.id = r->spec.id;
    rs.team = r->spec.team;
    rs.pose = pose(r->spec.id);
    rs.velocity = {r->body->GetLinearVelocity().x, r->body->GetLinearVelocity().y};
    rs.omega = r->body->GetAngularVelocity();
    rs.acceleration = r->drive_accel;
    rs.radius = r->spec.radius;
    rs.height = r->spec.height;
    s.robots.push_back(rs);
  }
  s.has_ball = ball_ != nullptr;
  if (ball_) {
    s.ball.position = {ball_->GetPosition().x, ball_->GetPosition().y};
    s.ball.velocity = {ball_->GetLinearVelocity().x, ball_->GetLinearVelocity().y};
    s.ball.radius = ball_radius_;
  }
  return s;
}

}  // namespace omniloc::sim
