#include "harness/camera_perception.hpp"

#include <algorithm>
#include <chrono>

#include "harness/vision_setup.hpp"
#include "localization/vision/entropy.hpp"

namespace omniloc::harness {

VisionConfig VisionConfig::from_json(const Json& j, const std::string& path, Json* effective) {
  JsonReader r(j, path, effective);
  r.allow("comment");
  VisionConfig v;
  v.calibration = r.string("calibration", std::string("auto"));
  v.colour_table = r.string("colour_table", std::string("auto"));
  if (auto s = r.object("scan_lines")) {
    v.scan = ScanLineParams::from_json(*s);
    s->finish();
  }
  if (auto e = r.object("exposure_control")) {
    v.exposure = ExposureParams::from_json(*e);
    e->finish();
  }
  if (auto b = r.object("blobs")) {
    v.blobs_detect = b->string("detect", std::string("auto"), {"auto", "on", "off"});
    v.blob_edge_colours_given = b->has("edge_colours");
    v.blobs = BlobParams::from_json(*b);
    b->finish();
  }
  r.finish();
  return v;
}

CameraPerception::CameraPerception(const Scenario& s, std::uint64_t seed)
    : CameraPerception(sim::CameraConfig::from_json(s.camera, "/camera"), s.field, VisionConfig::from_json(s.vision, "/vision"), seed) {}

CameraPerception::CameraPerception(const sim::CameraConfig& cfg, const Field& field, const VisionConfig& vc, std::uint64_t seed) : seed_(seed) {
  camera_ = std::make_unique<sim::PanoramicCamera>(cfg, field);
  map_ = calibration_for(cfg, vc.calibration, seed);
  table_ = colour_table_for(cfg, field, vc.colour_table, seed);
  detector_ = std::make_unique<LineDetector>(vc.scan, map_, table_);
  exposure_ = vc.exposure;
  exposure_.exposure_min = cfg.exposure_min;
  exposure_.exposure_max = cfg.exposure_max;
  exposure_.gain_min = cfg.gain_min;
  exposure_.gain_max = cfg.gain_max;
  if (vc.detect_blobs(field)) {
    BlobParams bp = vc.blobs;
    if (!vc.blob_edge_colours_given)
      for (const auto& g : field.goals) {
        const ColourClass c = landmark_colour_class(g.colour);
        if (c != kUnknown && std::find(bp.edge_colours.begin(), bp.edge_colours.end(), c) == bp.edge_colours.end())
          bp.edge_colours.push_back(c);
      }
    blob_detector_ = std::make_unique<BlobDetector>(bp, map_, table_);
  }
}

PerceptionOutput CameraPerception::observe(const sim::WorldState& world, int robot_id, double t, const FrameConditions& cond) {
  using Clock = std::chrono::steady_clock;
  PerceptionOutput out;
  auto it = rngs_.find(robot_id);
  if (it == rngs_.end()) it = rngs_.emplace(robot_id, Rng::stream(seed_, "camera/" + std::to_string(robot_id))).first;
  auto st = settings_.find(robot_id);
  if (st == settings_.end()) st = settings_.emplace(robot_id, camera_->config().initial).first;
  out.settings = st->second;
  const auto t0 = Clock::now();
  auto img = std::make_shared<Image>();
  if (cond.covered) {
    img->width = camera_->config().width;
    img->height = camera_->config().height;
    img->rgb.assign(static_cast<std::size_t>(img->width) * img->height * 3, 0);
  } else {
    *img = camera_->render(world, robot_id, st->second, it->second);
    sim::paint_sectors(*img, camera_->centre(), cond.occlusion);
  }
  const auto t1 = Clock::now();
  out.obs = detector_->observe(*img, t);
  if (blob_detector_ && out.obs.camera_ok) out.obs.blobs = blob_detector_->detect(*img);
  const auto t2 = Clock::now();
  out.render_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  out.vision_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  out.image = img;
  out.obs.image = img;
  // Entropy auto-adjustment (paper 002) on what the robot sees; never while the lens is covered.
  if (exposure_.enabled && !cond.covered && out.obs.camera_ok) {
    auto ct = controllers_.find(robot_id);
    if (ct == controllers_.end()) ct = controllers_.emplace(robot_id, ExposureController(exposure_, st->second)).first;
    // A frame taken while a search is running was taken at a trial setting: it is for the entropy
    // only. Paper 002 sec. 5 stops the robot "till the optimization is finished" so that it need not
    // localise on such frames; fed to the tracker, an over-exposed trial frame (up to 2000 false line
    // points under the sun) pulled the pose up to 0.9 m off while the robot stood still (docs/lighting.md "Auto-adjustment on was worse than off under field_robot").
    // The localizer coasts on odometry instead, which is exact for a robot standing still.
    const bool trial_frame = ct->second.searching();
    if (trial_frame) {
      out.obs.camera_ok = false;
      out.obs.line_points.clear();
      out.obs.blobs.clear();
    }
    const double body = centre_brightness(*img, map_.centre(), 0.8 * map_.min_radius());
    if (ct->second.wants_entropy()) out.entropy = image_entropy(*img, map_.centre(), map_.max_radius());
    ExposureDecision d = ct->second.update(t, body, out.entropy);
    st->second = d.settings;  // takes effect on the next frame
    out.stop_robot = d.searching;
    out.warnings.insert(out.warnings.end(), d.warnings.begin(), d.warnings.end());
    if (d.event) out.notes.push_back(*d.event);
  }
  return out;
}

std::unique_ptr<Perception> make_perception(const Scenario& s, bool needs_vision, std::uint64_t seed) {
  if (!needs_vision) return std::make_unique<NoPerception>();
  return std::make_unique<CameraPerception>(s, seed);
}

}  // namespace omniloc::harness
