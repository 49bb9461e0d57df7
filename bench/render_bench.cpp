// One 640 x 640 panorama per iteration, per GL back-end and quality, on a realistic scene: the
// MSL field, the observer, four other robots and the ball. Run with LP_NUM_THREADS=1 (one core).
#include <benchmark/benchmark.h>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "sim/render/panoramic_camera.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {

WorldState scene() {
  WorldState w;
  RobotState me;
  me.id = 0;
  me.pose = Pose2(-2.0, -1.5, 0.3);
  w.robots.push_back(me);
  const double xy[4][2] = {{0.5, -1.0}, {-3.5, 1.0}, {2.0, 3.0}, {-1.0, -4.0}};
  for (int i = 0; i < 4; ++i) {
    RobotState r;
    r.id = i + 1;
    r.pose = Pose2(xy[i][0], xy[i][1], 0.0);
    w.robots.push_back(r);
  }
  w.ball.position = {0.0, 0.5};
  return w;
}

void BM_RenderFrame(benchmark::State& state, const char* backend, const char* quality) {
  CameraConfig cfg;
  cfg.backend = backend;
  cfg.quality = quality;
  std::unique_ptr<PanoramicCamera> cam;
  try {
    cam = std::make_unique<PanoramicCamera>(cfg, Field::preset("msl2012"));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  WorldState w = scene();
  Rng rng(1);
  cam->render(w, 0, cfg.initial, rng);  // warm-up: lazy GL set-up (mipmaps, shader variants) is not per frame
  for (auto _ : state) {
    w.robots[0].pose = Pose2(w.robots[0].pose.x + 0.01, w.robots[0].pose.y, w.robots[0].pose.theta + 0.01);
    Image img = cam->render(w, 0, cfg.initial, rng);
    benchmark::DoNotOptimize(img.rgb.data());
  }
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_default, "osmesa", "default")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_high, "osmesa", "high")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_low, "osmesa", "low")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, egl_default, "egl", "default")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, egl_low, "egl", "low")->Unit(benchmark::kMillisecond)->UseRealTime();
