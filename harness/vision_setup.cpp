#include "harness/vision_setup.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/angles.hpp"
#include "core/cache_root.hpp"
#include "core/calibration_patch.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "harness/cache/cache_dirs.hpp"
#include "harness/scoring/metrics.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::harness {

namespace {
std::string fnv_hex(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : s) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  std::ostringstream os;
  os << std::hex << h;
  return os.str();
}
 
// A map or table computed because none was cached is kept for the next run; a cache that cannot be
// written only costs the computation next time (said once per process).
template <typename T>
void keep(const T& value, const std::string& file) {
  if (file.empty() || cache::unwritable()) return;
  try {
    value.save(file);
  } catch (const IoError& e) {
    cache::report_unwritable(e.what());
  }
}

// A cached file is used when it is a regular file that loads; anything else is computed again.
bool cached(const std::string& file) {
  std::error_code ec;
  return !file.empty() && std::filesystem::is_regular_file(file, ec);
}
}  // namespace

std::string camera_tag(const sim::CameraConfig& cfg) {
  Json j = cfg.to_json();
  j.erase("backend");  // the same optics whichever GL back-end draws them
  j.erase("quality");
  j.erase("latency_ms");  // latency changes when images arrive, not what the optics map
  j["photometry"] = sim::PanoramicCamera::kPhotometryVersion;
  return "cam-" + fnv_hex(j.dump());
}

CalibrationResult calibrate_camera(const sim::CameraConfig& cfg, std::uint64_t seed, Json* report, CentreSource centre_source) {
  // An empty floor large enough for the 8 m patch; the robot stands at the origin and turns.
  const Field floor = Field::from_json(Json{{"type", "plain"}, {"length", 22.0}, {"width", 14.0}, {"margin", 1.0}, {"wall_height", 0.0}}, "/calibration");
  // The robot turns slowly on the spot while calibrating, so the camera does not vibrate; pixel
  // noise stays.
  sim::CameraConfig still = cfg;
  still.vibration_std = 0.0;
  sim::PanoramicCamera cam(still, floor);
  sim::WorldState w;
  w.has_ball = false;
  sim::RobotState me;
  me.id = 0;
  w.robots.push_back(me);
  const auto& edges = calibration_patch::kEdgeDistances;
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    sim::FloorPatch p;
    p.centre = {0.5 * (edges[i] + edges[i + 1]), 0.0};
    p.half_size = {0.5 * (edges[i + 1] - edges[i]), 0.5 * calibration_patch::kStripWidth};
    p.reflectance = calibration_patch::stripe_is_white(static_cast<int>(i)) ? Eigen::Vector3d(0.85, 0.85, 0.85) : Eigen::Vector3d(0.03, 0.03, 0.03);
    w.floor_patches.push_back(p);
  }
  Rng rng = Rng::stream(seed, "calibration");
  std::vector<CalibrationView> views;
  for (int k = 0; k < calibration_patch::kDirections; ++k) {
    const double bearing = kTwoPi * k / calibration_patch::kDirections;
    w.robots[0].pose = Pose2(0, 0, -bearing);  // the patch along world +x appears at this robot bearing
    views.push_back({cam.render(w, 0, cfg.initial, rng), bearing});
  }
  // Model-free: the mirror axis is estimated from the rim in the images (never from the
  // simulator's centre()), or, for comparison, assumed at the image centre.
  // Edges the robot's own body hides cannot be found: a team measures where the floor disappears
  // under the body and lays the strip's first edges beyond it (NuBot's body hides 0.44 m, the
  // strip starts at 0.35 m; the default mirror's body 0.30 m).
  const double body = cam.body_radius_px() + 1.0;
  const auto hidden = cam.floor_point(cam.centre().x(), cam.centre().y() - (body + 3.0));
  const double body_floor = hidden ? hidden->norm() : 0.0;
  std::vector<double> edge_distances;
  for (double e : edges)
    if (e > body_floor + 0.02) edge_distances.push_back(e);
  CalibrationResult res = centre_source == CentreSource::kRim
                              ? calibrate_from_images(views, edge_distances, body)
                              : calibrate_from_images(views, edge_distances, Eigen::Vector2d(0.5 * cfg.width, 0.5 * cfg.height), body);
  res.map.tag = camera_tag(cfg);
  if (report) {
    // Error against the true mirror: project floor points at known distances, map them back.
    Json rows = Json::array();
    for (double d : {0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0}) {
      std::vector<double> errs;
      for (int k = 0; k < 72; ++k) {
        const double b = kTwoPi * k / 72 + 0.01;
        const auto px = cam.project({d * std::cos(b), d * std::sin(b), 0.0});
        if (!px) continue;
        const auto back = res.map.to_robot(px->x(), px->y());
        if (back) errs.push_back((*back - Eigen::Vector2d(d * std::cos(b), d * std::sin(b))).norm());
      }
      double mean = 0, mx = 0;
      for (double e : errs) {
        mean += e / errs.size();
        mx = std::max(mx, e);
      }
      rows.push_back({{"distance_m", d}, {"mean_error_m", mean}, {"p95_error_m", percentile(errs, 95)}, {"max_error_m", mx}, {"samples", errs.size()}});
    }
    const Eigen::Vector2d est = res.map.centre(), truth = cam.centre();
    *report = {{"directions_used", res.directions_used},
               {"directions_rejected", res.directions_rejected},
               {"centre_source", centre_source == CentreSource::kRim ? "rim" : "image-centre"},
               {"centre_px", {est.x(), est.y()}},
               {"true_centre_px", {truth.x(), truth.y()}},
               {"centre_error_px", (est - truth).norm()},
               {"rim_radius_px", res.rim.radius},
               {"true_rim_radius_px", cam.rim_px()},
               {"rim_rms_px", res.rim.rms_px},
               {"rim_points", res.rim.edge_points},
               {"rim_rejected", res.rim.rejected},
               {"error_by_distance", rows}};
  }
  return res;
}

ColourTable colour_calibrate(const sim::CameraConfig& cfg, const Field& field, std::uint64_t seed, int frames) {
  sim::PanoramicCamera cam(cfg, field);
  Rng rng = Rng::stream(seed, "colour-calibration");
  std::vector<Image> images, labels;
  const double hx = 0.5 * field.length - 0.5, hy = 0.5 * field.width - 0.5;
  for (int f = 0; f < frames; ++f) {
    sim::WorldState w;
    sim::RobotState me;
    me.id = 0;
    me.pose = Pose2(rng.uniform(-hx, hx), rng.uniform(-hy, hy), rng.uniform(-kPi, kPi));
    w.robots.push_back(me);
    for (int i = 1; i <= 3; ++i) {  // robots and the ball within a few metres, so their colours are seen up close
      sim::RobotState r;
      r.id = i;
      const double a = rng.uniform(0, kTwoPi), d = rng.uniform(1.0, 4.0);
      r.pose = Pose2(me.pose.x + d * std::cos(a), me.pose.y + d * std::sin(a), 0);
      w.robots.push_back(r);
    }
    const double a = rng.uniform(0, kTwoPi), d = rng.uniform(0.6, 3.0);
    w.ball.position = me.pose.translation() + d * Eigen::Vector2d(std::cos(a), std::sin(a));
    // Exposure and gain cycle through 0.94, 1 and 1.125 times the initial setting (0.88 to 1.27
    // times the brightness): under normal light the entropy search settles anywhere on the flat
    // top of its curve (16.9 to 20.25 from 18 on the tracking path), and a table learned at the
    // initial setting alone lost the carpet at 20.25. Dimmed lamps (0.35) or sun (2.2) stay far
    // outside this range.
    const double scale = std::array<double, 3>{1.0, 0.94, 1.125}[static_cast<std::size_t>(f) % 3];
    CameraSettings st = cfg.initial;
    st.exposure_ms *= scale;
    st.gain *= scale;
    images.push_back(cam.render(w, 0, st, rng));
    Image lab = cam.render_labels(w, 0);
    // White goals are the same white as the lines to a colour table: one "white" class (a real
    // table has no way to tell them apart, and with clipped whites the two would split the cell).
    for (std::size_t i = 0; i < lab.rgb.size(); ++i)
      if (lab.rgb[i] == sim::kLabelGoal) lab.rgb[i] = sim::kLabelLine;
    labels.push_back(std::move(lab));
  }
  // Coloured goals and landmarks: random poses may see them only far away and small, so one more
  // frame per object from 1-4 m, as a team would hold each landmark up to the camera. Fields
  // without coloured objects learn from exactly the frames above.
  std::vector<Eigen::Vector2d> targets;
  for (const auto& l : field.landmarks) targets.push_back(l.position);
  for (const auto& g : field.goals)
    if (g.colour != "white") targets.push_back({g.goal_line_x, 0.0});
  const double fx = field.half_floor_x() - 0.4, fy = field.half_floor_y() - 0.4;
  for (const auto& target : targets) {
    sim::WorldState w;
    w.has_ball = false;
    sim::RobotState me;
    me.id = 0;
    Eigen::Vector2d p = target;
    for (int attempt = 0; attempt < 50; ++attempt) {
      const double a = rng.uniform(0, kTwoPi), d = rng.uniform(1.0, 4.0);
      p = target + d * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (std::fabs(p.x()) <= fx && std::fabs(p.y()) <= fy && std::fabs(p.x()) <= 0.5 * field.length) break;
    }
    me.pose = Pose2(std::clamp(p.x(), -fx, fx), std::clamp(p.y(), -fy, fy), rng.uniform(-kPi, kPi));
    w.robots.push_back(me);
    images.push_back(cam.render(w, 0, cfg.initial, rng));
    labels.push_back(cam.render_labels(w, 0));
  }
  ColourTable t;
  t.learn(images, labels);
  t.field = field.fingerprint();
  return t;
}

CalibrationMap exact_calibration(const sim::CameraConfig& cfg) {
  // The simulator's own mirror, centre and mount, tabulated in the map's format (72 directions,
  // floor distances every 5 cm from the body's edge to 8 m, the model-free map's range).
  const sim::MirrorProfile mirror = sim::MirrorProfile::preset(cfg.mirror, cfg.rim_px(), cfg.mount_height);
  const double h = cfg.mount_height;
  const double d_body = h / std::tan(-mirror.elevation(mirror.body_radius()));
  std::vector<double> dist;
  for (double d = std::ceil((d_body + 0.01) / 0.05) * 0.05; d <= 8.0 + 1e-9; d += 0.05) dist.push_back(d);
  std::vector<double> radii;
  for (double d : dist) radii.push_back(mirror.radius(-std::atan2(h, d)));
  const int n = 72;
  CalibrationMap map;
  map.set_tables(cfg.width, cfg.height, cfg.mirror_centre_px(), std::vector<std::vector<double>>(n, radii), std::vector<std::vector<double>>(n, dist));
  map.tag = camera_tag(cfg);
  return map;
}

std::string calibration_cache_file(const sim::CameraConfig& cfg) {
  // v2: the mirror axis is estimated from the rim (docs/camera.md "The mirror centre"); "calibration_<tag>" files took the
  // image centre and are not reused.
  const std::string dir = build_cache_dir("vision");
  return dir.empty() ? dir : dir + "/calibration_v2_" + camera_tag(cfg) + ".json";
}

std::string colour_table_cache_file(const sim::CameraConfig& cfg, const Field& field) {
  // v2: learned over a range of exposures (colour_calibrate).
  const std::string dir = build_cache_dir("vision");
  return dir.empty() ? dir : dir + "/colour_v2_" + camera_tag(cfg) + "_" + field.fingerprint() + ".lut";
}

CalibrationMap calibration_for(const sim::CameraConfig& cfg, const std::string& path, std::uint64_t seed) {
  const std::string tag = camera_tag(cfg);
  if (path == "exact") return exact_calibration(cfg);
  if (path != "auto") return CalibrationMap::load(path, tag, cfg.width, cfg.height);
  const std::string file = calibration_cache_file(cfg);
  if (cached(file)) {
    try {
      return CalibrationMap::load(file, tag, cfg.width, cfg.height);
    } catch (const ConfigError&) {
      // A damaged cache entry is rebuilt below.
    }
  }
  // The cached map must not depend on which run made it first: a fixed seed, not the run's.
  (void)seed;
  CalibrationResult r = calibrate_camera(cfg, 1);
  keep(r.map, file);
  return r.map;
}

ColourTable colour_table_for(const sim::CameraConfig& cfg, const Field& field, const std::string& path, std::uint64_t seed) {
  if (path != "auto") return ColourTable::load(path, field.fingerprint());
  const std::string file = colour_table_cache_file(cfg, field);
  if (cached(file)) {
    try {
      return ColourTable::load(file, field.fingerprint());
    } catch (const ConfigError&) {
    }
  }
  (void)seed;
  ColourTable t = colour_calibrate(cfg, field, 1);
  keep(t, file);
  return t;
}

}  // namespace omniloc::harness
