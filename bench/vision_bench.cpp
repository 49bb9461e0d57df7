// Vision front end on one 640 x 640 rendered frame: colour classification + 72 radial scan lines +
// calibration map (target: <= 1.5 ms per frame on one core).
#include <benchmark/benchmark.h>

#include "core/field.hpp"
#include "harness/vision_setup.hpp"
#include "localization/vision/blobs.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/render/panoramic_camera.hpp"

using namespace omniloc;

static void BM_LinePointExtraction(benchmark::State& state) {
  sim::CameraConfig cfg;
  const Field field = Field::preset("msl2012");
  sim::PanoramicCamera cam(cfg, field);
  const CalibrationMap map = harness::calibrate_camera(cfg, 1).map;
  const ColourTable table = harness::colour_calibrate(cfg, field, 1, 6);
  const LineDetector det(ScanLineParams{}, map, table);
  sim::WorldState w;
  sim::RobotState me;
  me.pose = Pose2(-4.0, -1.0, 0.3);
  w.robots.push_back(me);
  Rng rng(1);
  const Image img = cam.render(w, 0, cfg.initial, rng);
  std::size_t points = 0;
  for (auto _ : state) {
    const ScanResult r = det.detect(img);
    points = r.points.size();
    benchmark::DoNotOptimize(r.points.data());
  }
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_LinePointExtraction)->Unit(benchmark::kMicrosecond);

// Blob detection on a frame of paper 003's cube arena (four cubes in view): classify the annulus,
// connected components per colour (yellow, blue, red), bearings / edges / contact distances.
static void BM_BlobDetection(benchmark::State& state) {
  sim::CameraConfig cfg;
  const Field field = Field::preset("arena_10x8");
  sim::PanoramicCamera cam(cfg, field);
  const CalibrationMap map = harness::calibrate_camera(cfg, 1).map;
  const ColourTable table = harness::colour_calibrate(cfg, field, 1, 6);
  const BlobDetector det(BlobParams{}, map, table);
  sim::WorldState w;
  w.has_ball = false;
  sim::RobotState me;
  me.pose = Pose2(1.0, 0.5, 0.4);
  w.robots.push_back(me);
  Rng rng(1);
  const Image img = cam.render(w, 0, cfg.initial, rng);
  std::size_t blobs = 0;
  for (auto _ : state) {
    const std::vector<Blob> b = det.detect(img);
    blobs = b.size();
    benchmark::DoNotOptimize(b.data());
  }
  state.counters["blobs"] = static_cast<double>(blobs);
}
BENCHMARK(BM_BlobDetection)->Unit(benchmark::kMicrosecond);
