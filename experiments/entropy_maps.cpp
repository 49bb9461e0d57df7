#include "experiments/entropy_maps.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>

#include <opencv2/imgproc.hpp>

#include "harness/camera_perception.hpp"
#include "harness/field_picture.hpp"
#include "harness/plot.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "harness/vision_setup.hpp"
#include "localization/vision/entropy.hpp"
#include "localization/vision/exposure_control.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::RunDirectory;
using harness::Scenario;
using harness::Series;
using harness::VisionConfig;
using harness::heat_map;
using harness::line_plot;
using harness::load_scenario;
using harness::png_bytes;
using harness::world_at;

namespace {

cv::Mat bgr_of(const Image& img) {
  cv::Mat rgb(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.rgb.data())), bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

struct Case {
  std::string name;
  Scenario sc;
};

}  // namespace

int run_entropy_maps(const ExperimentArgs& args, std::ostream& out) {
  const std::string dir_s = std::string(OMNILOC_SOURCE_DIR) + "/scenarios/paper/";
  std::vector<Case> cases = {{"normal", load_scenario(dir_s + "lighting_002.json")}, {"sun", load_scenario(dir_s + "lighting_002_sun.json")}};
  const Scenario& base = cases[0].sc;
  const sim::CameraConfig cfg = sim::CameraConfig::from_json(base.camera, "/camera");
  const VisionConfig vc = VisionConfig::from_json(base.vision, "/vision");
  CameraPerception rig(cfg, base.field, vc, args.seed);
  sim::PanoramicCamera& cam = rig.camera();
  const CalibrationMap& map = rig.calibration();
  const LineDetector& det = rig.detector();
  const int robot = base.localized_robots().front();
  RunDirectory dir(args.out_dir);
  const double step = args.quick ? 6.0 : 2.0, lo = 2.0, hi = 40.0;
  const int n = static_cast<int>(std::floor((hi - lo) / step + 1e-9)) + 1;
  Json result;
  std::vector<Series> line_series;
  out << "case   | peak on the grid (exposure ms, gain) | peak along exposure = gain | line points at 18/18 | at the auto-adjusted setting\n";
  for (auto& c : cases) {
    sim::WorldState ws = world_at(c.sc, 0.0, args.seed);
    auto render = [&](const CameraSettings& s, std::uint64_t k) {
      Rng rng = Rng::stream(args.seed, "entropy/" + std::to_string(k));
      return cam.render(ws, robot, s, rng);
    };
    auto entropy = [&](const Image& img) { return image_entropy(img, map.centre(), map.max_radius()); };
    // Entropy over the (exposure, gain) grid: rows = gain from high (top) to low.
    std::vector<double> grid(static_cast<std::size_t>(n) * n);
    double best = -1, best_e = 0, best_g = 0;
    std::uint64_t k = 0;
    for (int gi = 0; gi < n; ++gi)
      for (int ei = 0; ei < n; ++ei) {
        const CameraSettings s{lo + ei * step, lo + (n - 1 - gi) * step};
        const double h = entropy(render(s, k++));
        grid[static_cast<std::size_t>(gi) * n + ei] = h;
        if (h > best) best = h, best_e = s.exposure_ms, best_g = s.gain;
      }
    // Along the search line exposure = gain (a = 1, b = 0).
    Series line{c.name, {}, {}};
    double lbest = -1, lbest_g = 0;
    for (double g = 2.0; g <= 40.0 + 1e-9; g += args.quick ? 2.0 : 1.0) {
      const double h = entropy(render({g, g}, k++));
      line.x.push_back(g);
      line.y.push_back(h);
      if (h > lbest) lbest = h, lbest_g = g;
    }
    line_series.push_back(line);
    // The controller on this scene: settled under normal light at 18 / 18, then this case's light.
    ExposureParams ep = rig.exposure_params();
    ep.enabled = true;
    ep.search_at_start = false;  // settled under normal light first; the change of light triggers the search
    ExposureController ctl(ep, cfg.initial);
    const sim::Lighting target = ws.lighting;
    const Image before = [&] {
      Rng rng = Rng::stream(args.seed, "before");
      return cam.render(ws, robot, cfg.initial, rng);
    }();
    std::vector<std::pair<double, double>> path;
    std::string end_event;
    sim::WorldState normal = ws;
    normal.lighting = cases[0].sc.lighting_at(0.0);
    for (int f = 0; f < 200; ++f) {
      ws.lighting = f < 3 ? normal.lighting : target;
      const Image img = render(ctl.current(), k++);
      const double body = centre_brightness(img, map.centre(), 0.8 * map.min_radius());
      const double h = ctl.wants_entropy() ? entropy(img) : -1.0;
      const ExposureDecision d = ctl.update(f / 30.0, body, h);
      if (d.event && d.event->rfind("search_end", 0) == 0) {
        end_event = *d.event;
        break;
      }
    }
    ws.lighting = target;
    path = ctl.path();
    const Image after = render(ctl.current(), k++);
    const std::size_t pts_before = det.detect(before).points.size(), pts_after = det.detect(after).points.size();
    // Heat map with the search path (exposure = gain line) drawn on it.
    cv::Mat hm = heat_map(grid, n, n, lo, hi, hi, lo, "entropy (nats), " + c.name + " light", "exposure ms", "gain", args.quick ? 36 : 20);
    const int cell = args.quick ? 36 : 20, l = 70, t = 36;
    auto px = [&](double e, double g) {
      return cv::Point(static_cast<int>(l + ((e - lo) / step + 0.5) * cell), static_cast<int>(t + ((hi - g) / step + 0.5) * cell));
    };
    for (std::size_t i = 0; i < path.size(); ++i) {
      const cv::Point p = px(path[i].first, path[i].first);
      if (i > 0) cv::line(hm, px(path[i - 1].first, path[i - 1].first), p, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
      cv::circle(hm, p, 4, cv::Scalar(0, 0, 255), -1, cv::LINE_AA);
    }
    cv::drawMarker(hm, px(ctl.current().exposure_ms, ctl.current().gain), cv::Scalar(255, 255, 255), cv::MARKER_STAR, 16, 2);
    dir.write("entropy_" + c.name + ".png", png_bytes(hm));
    dir.write("frame_" + c.name + "_before.png", png_bytes(bgr_of(before)));
    dir.write("frame_" + c.name + "_after.png", png_bytes(bgr_of(after)));
    char buf[300];
    std::snprintf(buf, sizeof buf, "%-6s | %13.0f %7.0f %13s | %14.0f (H = %.2f)     | %20zu | %zu at %.1f / %.1f\n", c.name.c_str(), best_e, best_g, "", lbest_g, lbest,
                  pts_before, pts_after, ctl.current().exposure_ms, ctl.current().gain);
    out << buf;
    Json jp = Json::array();
    for (const auto& [g, h] : path) jp.push_back({g, h});
    result[c.name] = {{"grid", {{"exposure_ms", {lo, hi, step}}, {"gain", {hi, lo, -step}}, {"entropy", grid}}},
                      {"grid_peak", {best_e, best_g, best}},
                      {"line", {{"gain", line.x}, {"entropy", line.y}}},
                      {"line_peak_gain", lbest_g},
                      {"search_path", jp},
                      {"search_end", end_event},
                      {"adjusted", {ctl.current().exposure_ms, ctl.current().gain}},
                      {"line_points", {{"before", pts_before}, {"after", pts_after}}}};
  }
  dir.write("entropy_line.png", png_bytes(line_plot(line_series, "entropy along exposure = gain", "gain (= exposure ms)", "entropy, nats")));
  dir.write("entropy_maps.json", result.dump(1) + "\n");
  dir.commit();
  out << "figures: " << dir.final_dir() << "/{entropy_normal,entropy_sun,entropy_line,frame_*}.png\n";
  return 0;
}

}  // namespace omniloc::experiments
