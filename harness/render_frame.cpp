#include "harness/render_frame.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "harness/camera_perception.hpp"
#include "harness/image_file.hpp"
#include "harness/simulation.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::harness {

sim::WorldState world_at(const Scenario& s, double t, std::uint64_t seed) {
  Simulation sim(s, seed);
  sim.advance_to(t);
  return sim.state();
}

namespace {

// Replays the run's camera frames 0..k_last; returns robot's image of frame k_last (with `labels`, the
// class image of the same world: the pauses earlier frames asked for are replayed all the same).
Image replayed_frame(const Scenario& s, long long k_last, int robot, std::uint64_t seed, bool labels, CameraPerception& perception) {
  Simulation sim(s, seed);
  const std::vector<int> localized = s.localized_robots();
  const bool is_localized = std::find(localized.begin(), localized.end(), robot) != localized.end();
  for (long long k = 0; k <= k_last; ++k) {
    sim.advance_to(static_cast<double>(k) / s.camera_rate);
    const sim::WorldState now = sim.state();
    if (k == k_last && labels) return perception.camera().render_labels(sim.camera_view(now), robot);
    for (int id : localized) {
      const PerceptionOutput po = perception.observe(sim.camera_view(now), id, now.t, sim.conditions(id, now));
      sim.set_paused(id, po.stop_robot);
      if (k == k_last && id == robot) return *po.image;
    }
    if (k == k_last && !is_localized) return *perception.observe(sim.camera_view(now), robot, now.t, sim.conditions(robot, now)).image;
  }
  throw RuntimeFailure("no frame " + std::to_string(k_last));
}

}  // namespace

void write_png(const Image& img, const std::string& path) {
  cv::Mat rgb(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  // The encoder follows the extension (.png by default; .jpg for small pictures in docs).
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  write_file_atomic(path, ext == ".jpg" || ext == ".jpeg" ? encode_jpeg(bgr, 88) : encode_png(bgr));
}

void render_to_png(const Scenario& s, double t, int robot_id, std::uint64_t seed, bool labels, const std::string& png_path, bool points) {
  if (!s.robot(robot_id)) throw ConfigError("--robot", std::to_string(robot_id), "the id of a robot in the scenario");
  if (t < 0 || t > s.duration) throw ConfigError("--t", std::to_string(t), "a time within the scenario's duration");
  const long long k = static_cast<long long>(std::floor(t * s.camera_rate + 1e-9));
  CameraPerception perception(s, seed);
  Image img = replayed_frame(s, k, robot_id, seed, labels, perception);
  if (labels)
    for (auto& v : img.rgb) v = static_cast<std::uint8_t>(std::min(255, v * 21));  // class ids spread over the grey range
  if (points && !labels) {
    const ScanResult r = perception.detector().detect(img);
    cv::Mat m(img.height, img.width, CV_8UC3, img.rgb.data());
    for (const auto& p : r.pixels) cv::circle(m, cv::Point(static_cast<int>(p.x()), static_cast<int>(p.y())), 3, cv::Scalar(255, 0, 0), 1);
  }
  write_png(img, png_path);
}

}  // namespace omniloc::harness
