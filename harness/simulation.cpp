#include "harness/simulation.hpp"

#include "harness/events.hpp"

namespace omniloc::harness {

namespace {

// What each event kind (harness/events.hpp) does to the running simulation, and what events.jsonl
// records of it. Here rather than in events.cpp: the events are the scenario's data, the simulation
// is what acts on them.

// Teleport and kidnap move the robot alike: to the given pose or one drawn from the stream "events".
template <class K>
void move_robot(const K& k, const Event& e, Simulation& sim, Json& log) {
  const Pose2 target = k.random_pose ? sim.random_pose_on_field() : k.pose;
  sim.teleport(e.robot, target);
  log["pose"] = {target.x, target.y, target.theta};
}

void apply(const Teleport& k, const Event& e, Simulation& sim, Json& log) { move_robot(k, e, sim, log); }

void apply(const Cover& k, const Event& e, Simulation& sim, Json& log) {
  sim.cover_camera(e.robot, sim.time() + k.duration);
  log["duration"] = k.duration;
}

// A kidnap is a teleport under a covered camera.
void apply(const Kidnap& k, const Event& e, Simulation& sim, Json& log) {
  move_robot(k, e, sim, log);
  apply(Cover{k.duration}, e, sim, log);
}

void apply(const Occlude& k, const Event& e, Simulation& sim, Json& log) {
  sim.occlude_camera(e.robot, sim.time() + k.duration, k.mask);
  log["duration"] = k.duration;
  log["fraction"] = k.mask.fraction();
}

// The light is a function of time (Scenario::lighting_at, through Lights::shade): nothing to change.
void apply(const Lights& k, const Event&, Simulation&, Json& log) {
  log["level"] = k.level;
  log["transition"] = k.transition;
}

void apply(const Slip& k, const Event& e, Simulation& sim, Json& log) {
  sim.slip_wheels(e.robot, sim.time() + k.duration, k.scale);
  log["duration"] = k.duration;
  log["scale"] = k.scale;
}

Json apply_event(const Event& e, Simulation& sim) {
  Json log{{"t", sim.time()}, {"type", e.type()}, {"robot", e.robot}};
  std::visit([&](const auto& k) { apply(k, e, sim, log); }, e.kind);
  return log;
}

}  // namespace

Simulation::Simulation(const Scenario& s, std::uint64_t seed, EventLog* log)
    : sc_(s), log_(log), world_(s.field, s.physics_rate), event_rng_(Rng::stream(seed, "events")) {
  for (const auto& rc : s.robots) {
    world_.add_robot(rc.spec);
    const std::string id = std::to_string(rc.spec.id);
    scripts_[rc.spec.id] = sim::MotionScript::from_json(rc.motion, rc.motion_path, derive_seed(seed, "motion/" + id), &s.field);
  }
  if (s.has_ball) world_.set_ball(s.ball_position, s.ball_velocity);
  for (int id : s.localized_robots()) {
    const RobotConfig& rc = *s.robot(id);
    Sensors& se = sensors_[id];
    se.odometry = std::make_unique<sim::OdometrySensor>(rc.odometry, Rng::stream(seed, "odometry/" + std::to_string(id)));
    se.heading = std::make_unique<sim::HeadingSensor>(rc.heading, Rng::stream(seed, "heading/" + std::to_string(id)));
    se.has_heading = rc.has_heading_sensor;
  }
  // Camera latency: the image shows the world as it was `latency` seconds before the frame time.
  latency_ = s.camera.value("latency_ms", 0.0) * 1e-3;
}

Simulation::~Simulation() = default;

double Simulation::time() const { return world_.time(); }

void Simulation::advance_to(double t) {
  const double dt = world_.dt();
  // No tolerance: time() is exact in steps, so the loop stops at the first step at or after t
  // (docs/protocol.md: a frame's t is never before k / camera_rate).
  while (world_.time() < t) {
    while (next_event_ < sc_.events.size() && sc_.events[next_event_].t <= world_.time() + 1e-9) {
      const Json record = apply_event(sc_.events[next_event_++], *this);
      if (log_) log_->add(record);
    }
    const sim::WorldState ws = world_.state();
    for (const auto& rc : sc_.robots)
      world_.command(rc.spec.id, paused(rc.spec.id) ? sim::DriveCommand{} : scripts_[rc.spec.id]->command(ws, rc.spec.id, world_.time()));
    world_.step();
    if (latency_ > 0) {
      history_.push_back(world_.state());
      while (history_.size() > 1 && history_[1].t <= world_.time() - latency_ - 1e-9) history_.pop_front();
    }
    for (auto& [id, se] : sensors_) {
      const Pose2 wheels = world_.wheel_motion(id);
      // The step that ends at world_.time() started before slip_until: it slipped.
      const bool slipping = world_.time() - dt < se.slip_until - 1e-9;
      se.odometry->accumulate(slipping ? Pose2(wheels.x * se.slip_scale, wheels.y * se.slip_scale, wheels.theta * se.slip_scale) : wheels);
      se.heading->advance(dt);
    }
  }
}

sim::WorldState Simulation::state() const {
  sim::WorldState ws = world_.state();
  ws.lighting = sc_.lighting_at(ws.t);
  return ws;
}

sim::WorldState Simulation::camera_view(const sim::WorldState& now) const {
  if (!(latency_ > 0) || history_.empty() || history_.front().t > now.t - latency_ + 1e-9) return now;
  const sim::WorldState* past = &history_.front();
  for (const auto& h : history_)
    if (h.t <= now.t - latency_ + 1e-9) past = &h;
  sim::WorldState seen = *past;
  seen.lighting = now.lighting;
  return seen;
}

FrameConditions Simulation::conditions(int robot, const sim::WorldState& now) const {
  FrameConditions cond;
  const double theta = now.robot(robot)->pose.theta;
  // Whole-run mask and event masks together (event masks may overlap the run's mask).
  cond.occlusion = sc_.occlusion.robot_frame(theta);
  auto it = cameras_.find(robot);
  if (it == cameras_.end()) return cond;
  cond.covered = now.t < it->second.covered_until;
  if (now.t < it->second.occluded_until)
    for (const auto& sector : it->second.mask.robot_frame(theta)) cond.occlusion.push_back(sector);
  return cond;
}

SensorReadings Simulation::read_sensors(int robot, const sim::WorldState& now) {
  Sensors& se = sensors_.at(robot);
  SensorReadings r;
  r.odometry = se.odometry->read(now.t);
  if (se.has_heading) r.heading = se.heading->read(now.t, now.robot(robot)->pose.theta).heading;
  return r;
}

bool Simulation::in_contact(int robot) const { return world_.in_contact(robot); }

void Simulation::set_paused(int robot, bool p) { paused_[robot] = p; }

bool Simulation::paused(int robot) const {
  auto it = paused_.find(robot);
  return it != paused_.end() && it->second;
}

void Simulation::teleport(int robot, const Pose2& pose) {
  world_.teleport(robot, pose);
  scripts_[robot]->on_teleport();
}

void Simulation::cover_camera(int robot, double until) { cameras_[robot].covered_until = until; }

void Simulation::occlude_camera(int robot, double until, const sim::OcclusionMask& mask) {
  cameras_[robot].occluded_until = until;
  cameras_[robot].mask = mask;
}

void Simulation::slip_wheels(int robot, double until, double scale) {
  auto it = sensors_.find(robot);
  if (it == sensors_.end()) return;  // a robot that is not localized has no odometry to fool
  it->second.slip_until = until;
  it->second.slip_scale = scale;
}

Pose2 Simulation::random_pose_on_field() {
  const Field& f = sc_.field;
  const double x = event_rng_.uniform(-0.5 * f.length + 0.5, 0.5 * f.length - 0.5);
  const double y = event_rng_.uniform(-0.5 * f.width + 0.5, 0.5 * f.width - 0.5);
  return Pose2(x, y, event_rng_.uniform(-kPi, kPi));
}

}  // namespace omniloc::harness
