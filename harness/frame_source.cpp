#include "harness/frame_source.hpp"

#include <cmath>

#include "harness/camera_perception.hpp"
#include "harness/external_session.hpp"

namespace omniloc::harness {

std::vector<std::string> perception_events(const PerceptionOutput& po, int robot, double t, bool was_paused) {
  std::vector<std::string> lines;
  for (const auto& w : po.warnings) lines.push_back(Json{{"t", t}, {"type", "warning"}, {"robot", robot}, {"message", w}}.dump());
  for (const auto& n : po.notes)
    lines.push_back(Json{{"t", t}, {"type", "camera"}, {"robot", robot}, {"message", n}, {"exposure_ms", po.settings.exposure_ms}, {"gain", po.settings.gain}}
                        .dump());
  if (po.stop_robot != was_paused) lines.push_back(Json{{"t", t}, {"type", po.stop_robot ? "pause" : "resume"}, {"robot", robot}}.dump());
  return lines;
}

LiveSource::LiveSource(const Scenario& sc, std::uint64_t seed, bool camera)
    : sc_(sc), sim_(sc, seed, &log_), perception_(make_perception(sc, camera, seed)), camera_(camera) {
  // The first frame at t = 0 before any motion, the last at floor(duration x rate).
  n_frames_ = static_cast<long long>(std::floor(sc.duration * sc.camera_rate + 1e-9)) + 1;
}

LiveSource::~LiveSource() = default;

std::optional<FrameData> LiveSource::next() {
  if (k_ >= n_frames_) return std::nullopt;
  FrameData f;
  f.k = k_++;
  sim_.advance_to(static_cast<double>(f.k) / sc_.camera_rate);
  const sim::WorldState now = sim_.state();
  f.t = now.t;
  // The scenario's events applied on the way to this frame, in the order they happened.
  const std::string& text = log_.text();
  for (std::size_t a = log_read_, b; a < text.size(); a = b + 1) {
    b = text.find('\n', a);
    f.events.push_back(text.substr(a, b - a));
  }
  log_read_ = text.size();
  for (int id : sc_.localized_robots()) {
    RobotFrame r;
    r.id = id;
    const FrameConditions cond = sim_.conditions(id, now);
    const SensorReadings sensors = sim_.read_sensors(id, now);
    PerceptionOutput po = perception_->observe(sim_.camera_view(now), id, now.t, cond);
    r.odometry = sensors.odometry;
    r.heading = sensors.heading;
    r.covered = cond.covered;
    if (po.image) r.settings = po.settings;
    r.stop_robot = po.stop_robot;
    r.events = perception_events(po, id, now.t, sim_.paused(id));
    r.render_ms = po.render_ms;
    r.vision_ms = po.vision_ms;
    r.obs = std::move(po.obs);
    r.truth = now.robot(id)->pose;
    r.contact = sim_.in_contact(id);
    f.robots.push_back(std::move(r));
  }
  // Pauses take effect from the next physics step, after every robot of this frame was seen.
  for (const auto& r : f.robots) sim_.set_paused(r.id, r.stop_robot);
  return f;
}

Json LiveSource::client_camera(int) const { return camera_for_client(perception_->calibration_map()); }

bool LiveSource::detects_blobs() const { return perception_->detects_blobs(); }

Json LiveSource::render_device() const {
  const auto dev = perception_->render_device();
  return dev ? dev->to_json() : Json(nullptr);
}

}  // namespace omniloc::harness
