#include "harness/render_frame.hpp"

#include <map>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "harness/camera_perception.hpp"
#include "harness/vision_setup.hpp"
#include "sim/motion.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "sim/world.hpp"

namespace omniloc::harness {

sim::WorldState world_at(const Scenario& s, double t, std::uint64_t seed) {
  sim::World world(s.field, 1.0 / s.physics_rate);
  std::map<int, std::unique_ptr<sim::MotionScript>> scripts;
  for (const auto& rc : s.robots) {
    world.add_robot(rc.spec);
    scripts[rc.spec.id] = sim::MotionScript::from_json(rc.motion, rc.motion_path, derive_seed(seed, "motion/" + std::to_string(rc.spec.id)), &s.field);
  }
  if (s.has_ball) world.set_ball(s.ball_position, s.ball_velocity);
  std::size_t next = 0;
  Rng event_rng = Rng::stream(seed, "events");  // as in the run loop, so random targets agree
  while (world.time() < t - 1e-9) {
    while (next < s.events.size() && s.events[next].t <= world.time() + 1e-9) {
      const auto& e = s.events[next++];
      if (e.type == "teleport" || e.type == "kidnap") {
        world.teleport(e.robot, s.event_target(e, event_rng));
        scripts[e.robot]->on_teleport();
      }
    }
    const sim::WorldState ws = world.state();
    for (const auto& rc : s.robots) world.command(rc.spec.id, scripts[rc.spec.id]->command(ws, rc.spec.id, world.time()));
    world.step();
  }
  sim::WorldState ws = world.state();
  ws.lighting = s.lighting_at(ws.t);
  return ws;
}

void write_png(const Image& img, const std::string& path) {
  cv::Mat rgb(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<uchar> buf;
  // The encoder follows the extension (.png by default; .jpg for small pictures in docs).
  const auto dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  if (ext != ".jpg" && ext != ".jpeg") ext = ".png";
  if (!cv::imencode(ext, bgr, buf, ext == ".png" ? std::vector<int>{} : std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 88}))
    throw RuntimeFailure("cannot encode " + ext + " for " + path);
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(buf.data()), buf.size()));
}

void render_to_png(const Scenario& s, double t, int robot_id, std::uint64_t seed, bool labels, const std::string& png_path, bool points) {
  if (!s.robot(robot_id)) throw ConfigError("--robot", std::to_string(robot_id), "the id of a robot in the scenario");
  if (t < 0 || t > s.duration) throw ConfigError("--t", std::to_string(t), "a time within the scenario's duration");
  const sim::CameraConfig cfg = sim::CameraConfig::from_json(s.camera, "/camera");
  sim::PanoramicCamera cam(cfg, s.field);
  const sim::WorldState ws = world_at(s, t, seed);
  Rng rng = Rng::stream(seed, "camera/" + std::to_string(robot_id));
  Image img = labels ? cam.render_labels(ws, robot_id) : cam.render(ws, robot_id, cfg.initial, rng);
  if (labels)  // spread the class ids over the grey range so the picture is readable
    for (auto& v : img.rgb) v = static_cast<std::uint8_t>(std::min(255, v * 21));
  if (points && !labels) {
    const VisionConfig vc = VisionConfig::from_json(s.vision, "/vision");
    const CalibrationMap map = calibration_for(cfg, vc.calibration, seed);
    const ColourTable table = colour_table_for(cfg, s.field, vc.colour_table, seed);
    const LineDetector det(vc.scan, map, table);
    const ScanResult r = det.detect(img);
    cv::Mat m(img.height, img.width, CV_8UC3, img.rgb.data());
    for (const auto& p : r.pixels) cv::circle(m, cv::Point(static_cast<int>(p.x()), static_cast<int>(p.y())), 3, cv::Scalar(255, 0, 0), 1);
  }
  write_png(img, png_path);
}

}  // namespace omniloc::harness
