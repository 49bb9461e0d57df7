#include "experiments/entropy_maps.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>

#include <opencv2/imgproc.hpp>

#include "experiments/report_format.hpp"
#include "harness/camera_perception.hpp"
#include "experiments/field_picture.hpp"
#include "experiments/plot.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "harness/vision_setup.hpp"
#include "localization/vision/entropy.hpp"
#include "localization/vision/exposure_control.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "core/install_paths.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::RunDirectory;
using harness::Scenario;
using harness::VisionConfig;
using harness::load_scenario;
using harness::world_at;

// --- configuration --------------------------------------------------------------------------------------

int EntropyMapsConfig::grid_size() const { return static_cast<int>(std::floor((hi - lo) / step + 1e-9)) + 1; }

EntropyMapsConfig EntropyMapsConfig::from_args(const ExperimentArgs& args) {
  const std::string dir = (share_dir() / "scenarios/paper").string() + "/";
  EntropyMapsConfig c;
  c.cases = {{"normal", dir + "lighting_002.json"}, {"sun", dir + "lighting_002_sun.json"}};
  c.step = args.quick ? 6.0 : 2.0;
  c.line_step = args.quick ? 2.0 : 1.0;
  c.cell_px = args.quick ? 36 : 20;
  c.seed = args.seed;
  c.quick = args.quick;
  return c;
}

// --- computation ----------------------------------------------------------------------------------------

namespace {

/// Renders one case's scene at given settings, each frame with its own numbered noise stream.
struct CaseCamera {
  sim::PanoramicCamera& cam;
  sim::WorldState ws;
  int robot;
  std::uint64_t seed;
  const CalibrationMap& map;
  std::uint64_t k = 0;  ///< frames rendered so far (the next frame's stream number)
  Image render(const CameraSettings& s) {
    Rng rng = Rng::stream(seed, "entropy/" + std::to_string(k++));
    return cam.render(ws, robot, s, rng);
  }
  double entropy(const Image& img) const { return image_entropy(img, map.centre(), map.max_radius()); }
};

/// Entropy over the (exposure, gain) grid and along the search line exposure = gain (a = 1, b = 0).
void entropy_grid_and_line(const EntropyMapsConfig& cfg, CaseCamera& cc, EntropyCase& r) {
  const int n = cfg.grid_size();
  r.grid.assign(static_cast<std::size_t>(n) * n, 0.0);
  for (int gi = 0; gi < n; ++gi)
    for (int ei = 0; ei < n; ++ei) {
      const CameraSettings s{cfg.lo + ei * cfg.step, cfg.lo + (n - 1 - gi) * cfg.step};
      const double h = cc.entropy(cc.render(s));
      r.grid[static_cast<std::size_t>(gi) * n + ei] = h;
      if (h > r.grid_best) r.grid_best = h, r.grid_best_exposure = s.exposure_ms, r.grid_best_gain = s.gain;
    }
  for (double g = 2.0; g <= 40.0 + 1e-9; g += cfg.line_step) {
    const double h = cc.entropy(cc.render({g, g}));
    r.line_gain.push_back(g);
    r.line_entropy.push_back(h);
    if (h > r.line_best) r.line_best = h, r.line_best_gain = g;
  }
}

/// The controller on this scene: settled under normal light at the initial setting, then this case's light.
void adjust_exposure(CameraPerception& rig, const CameraSettings& initial, const sim::Lighting& normal_light, CaseCamera& cc, EntropyCase& r) {
  ExposureParams ep = rig.exposure_params();
  ep.enabled = true;
  ep.search_at_start = false;  // settled under normal light first; the change of light triggers the search
  ExposureController ctl(ep, initial);
  const sim::Lighting target = cc.ws.lighting;
  const CalibrationMap& map = cc.map;
  for (int f = 0; f < 200; ++f) {
    cc.ws.lighting = f < 3 ? normal_light : target;
    const Image img = cc.render(ctl.current());
    const double body = centre_brightness(img, map.centre(), 0.8 * map.min_radius());
    const double h = ctl.wants_entropy() ? cc.entropy(img) : -1.0;
    const ExposureDecision d = ctl.update(f / 30.0, body, h);
    if (d.event && d.event->rfind("search_end", 0) == 0) {
      r.search_end = *d.event;
      break;
    }
  }
  cc.ws.lighting = target;
  r.search_path = ctl.path();
  r.adjusted = ctl.current();
  r.after = cc.render(ctl.current());
}

}  // namespace

EntropyMapsResult compute_entropy_maps(const EntropyMapsConfig& cfg) {
  std::vector<std::pair<std::string, Scenario>> cases;
  for (const auto& [name, file] : cfg.cases) cases.emplace_back(name, load_scenario(file));
  const Scenario& base = cases[0].second;
  const sim::CameraConfig camera = sim::CameraConfig::from_json(base.camera, "/camera");
  const VisionConfig vc = VisionConfig::from_json(base.vision, "/vision");
  CameraPerception rig(camera, base.field, vc, cfg.seed);
  const int robot = base.localized_robots().front();
  EntropyMapsResult result;
  for (const auto& [name, sc] : cases) {
    EntropyCase r;
    r.name = name;
    CaseCamera cc{rig.camera(), world_at(sc, 0.0, cfg.seed), robot, cfg.seed, rig.calibration()};
    entropy_grid_and_line(cfg, cc, r);
    r.before = [&] {
      Rng rng = Rng::stream(cfg.seed, "before");
      return cc.cam.render(cc.ws, robot, camera.initial, rng);
    }();
    adjust_exposure(rig, camera.initial, base.lighting_at(0.0), cc, r);
    r.points_before = rig.detector().detect(r.before).points.size();
    r.points_after = rig.detector().detect(r.after).points.size();
    result.cases.push_back(std::move(r));
  }
  return result;
}

// --- report ---------------------------------------------------------------------------------------------

namespace {

cv::Mat bgr_of(const Image& img) {
  cv::Mat rgb(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.rgb.data())), bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

/// The entropy heat map with the search path (on the exposure = gain line) and the adjusted setting.
cv::Mat search_figure(const EntropyMapsConfig& cfg, const EntropyCase& c) {
  const int n = cfg.grid_size();
  const double lo = cfg.lo, hi = cfg.hi, step = cfg.step;
  cv::Mat hm = heat_map(c.grid, n, n, lo, hi, hi, lo, "entropy (nats), " + c.name + " light", "exposure ms", "gain", cfg.cell_px);
  const int cell = cfg.cell_px, l = 70, t = 36;
  auto px = [&](double e, double g) {
    return cv::Point(static_cast<int>(l + ((e - lo) / step + 0.5) * cell), static_cast<int>(t + ((hi - g) / step + 0.5) * cell));
  };
  const auto& path = c.search_path;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const cv::Point p = px(path[i].first, path[i].first);
    if (i > 0) cv::line(hm, px(path[i - 1].first, path[i - 1].first), p, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
    cv::circle(hm, p, 4, cv::Scalar(0, 0, 255), -1, cv::LINE_AA);
  }
  cv::drawMarker(hm, px(c.adjusted.exposure_ms, c.adjusted.gain), cv::Scalar(255, 255, 255), cv::MARKER_STAR, 16, 2);
  return hm;
}

Json case_json(const EntropyMapsConfig& cfg, const EntropyCase& c) {
  const double lo = cfg.lo, hi = cfg.hi, step = cfg.step;
  Json jp = Json::array();
  for (const auto& [g, h] : c.search_path) jp.push_back({g, h});
  return {{"grid", {{"exposure_ms", {lo, hi, step}}, {"gain", {hi, lo, -step}}, {"entropy", c.grid}}},
          {"grid_peak", {c.grid_best_exposure, c.grid_best_gain, c.grid_best}},
          {"line", {{"gain", c.line_gain}, {"entropy", c.line_entropy}}},
          {"line_peak_gain", c.line_best_gain},
          {"search_path", jp},
          {"search_end", c.search_end},
          {"adjusted", {c.adjusted.exposure_ms, c.adjusted.gain}},
          {"line_points", {{"before", c.points_before}, {"after", c.points_after}}}};
}

}  // namespace

void write_entropy_maps_report(const EntropyMapsConfig& cfg, const EntropyMapsResult& r, RunDirectory& dir, std::ostream& out) {
  Json result;
  std::vector<Series> line_series;
  out << "case   | peak on the grid (exposure ms, gain) | peak along exposure = gain | line points at 18/18 | at the auto-adjusted setting\n";
  for (const auto& c : r.cases) {
    line_series.push_back(Series{c.name, c.line_gain, c.line_entropy});
    dir.write("entropy_" + c.name + ".png", png_bytes(search_figure(cfg, c)));
    dir.write("frame_" + c.name + "_before.png", png_bytes(bgr_of(c.before)));
    dir.write("frame_" + c.name + "_after.png", png_bytes(bgr_of(c.after)));
    out << strprintf("%-6s | %13.0f %7.0f %13s | %14.0f (H = %.2f)     | %20zu | %zu at %.1f / %.1f\n", c.name.c_str(), c.grid_best_exposure,
                     c.grid_best_gain, "", c.line_best_gain, c.line_best, c.points_before, c.points_after, c.adjusted.exposure_ms, c.adjusted.gain);
    result[c.name] = case_json(cfg, c);
  }
  dir.write("entropy_line.png", png_bytes(line_plot(line_series, "entropy along exposure = gain", "gain (= exposure ms)", "entropy, nats")));
  dir.write("entropy_maps.json", result.dump(1) + "\n");
  dir.commit();
  out << "figures: " << dir.final_dir() << "/{entropy_normal,entropy_sun,entropy_line,frame_*}.png\n";
}

// --- the experiment -------------------------------------------------------------------------------------

int run_entropy_maps(const ExperimentArgs& args, std::ostream& out) {
  const EntropyMapsConfig cfg = EntropyMapsConfig::from_args(args);
  RunDirectory dir(args.out_dir);  // refuses an unusable output folder before any work
  const EntropyMapsResult r = compute_entropy_maps(cfg);
  write_entropy_maps_report(cfg, r, dir, out);
  return 0;
}

}  // namespace omniloc::experiments
