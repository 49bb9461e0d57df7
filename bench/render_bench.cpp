// One 640 x 640 panorama per iteration, per GL back-end and quality, on a realistic scene: the
// MSL field, the observer, four other robots and the ball. Run with LP_NUM_THREADS=1 (one core).
//
// BM_RenderProfile (docs/performance.md "The cost of a field_robot frame") draws the same scene with the observer driving at 1 m/s (the paper
// tracking path's speed, no turn) under the camera settings of the `robot` and `field_robot` noise
// profiles (data/noise_profiles.json), so that the ratio of the two is measured in one run;
// `field_robot_turning` adds a 2 rad/s turn (the rotation smear), and the `field_robot_no_*`
// captures leave one effect out (what each costs). BM_Optics times the CPU-side pieces alone on a
// rendered buffer.
#include <benchmark/benchmark.h>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "sim/render/mirror.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "sim/render/photometry.hpp"

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

// The camera of `cfg` on the MSL field, or null with the benchmark skipped (no GL back-end here).
std::unique_ptr<PanoramicCamera> make_camera(benchmark::State& state, const CameraConfig& cfg) {
  try {
    return std::make_unique<PanoramicCamera>(cfg, Field::preset("msl2012"));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return nullptr;
  }
}

void BM_RenderFrame(benchmark::State& state, const char* backend, const char* quality) {
  CameraConfig cfg;
  cfg.backend = backend;
  cfg.quality = quality;
  const std::unique_ptr<PanoramicCamera> cam = make_camera(state, cfg);
  if (!cam) return;
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

// The camera of a noise profile (data/noise_profiles.json: robot keeps the camera's defaults;
// field_robot adds defocus, motion blur, tilt from acceleration and a decentred mirror).
enum class Effects { kRobot, kFieldRobot, kNoMotionBlur, kNoDefocus };

CameraConfig profile_camera(Effects e) {
  CameraConfig cfg;
  if (e == Effects::kRobot) return cfg;
  cfg.optical_blur_px = e == Effects::kNoDefocus ? 0.0 : 2.5;
  cfg.focus_radius_fraction = 0.5;
  cfg.motion_blur = e != Effects::kNoMotionBlur;
  cfg.tilt_per_accel = 0.1 * 3.14159265358979323846 / 180.0;
  cfg.centre_offset_px = {6.4, -6.4};
  return cfg;
}

// The observer drives at 1 m/s along its heading (exposure 18 ms: 1.8 cm of travel), turning at
// `omega` rad/s; each iteration is the next frame at 30 Hz.
void BM_RenderProfile(benchmark::State& state, Effects e, double omega) {
  const CameraConfig cfg = profile_camera(e);
  const std::unique_ptr<PanoramicCamera> cam = make_camera(state, cfg);
  if (!cam) return;
  WorldState w = scene();
  auto step = [&](double dt) {
    RobotState& me = w.robots[0];
    me.pose = Pose2(me.pose.x + dt * std::cos(me.pose.theta), me.pose.y + dt * std::sin(me.pose.theta), me.pose.theta + omega * dt);
    me.velocity = {std::cos(me.pose.theta), std::sin(me.pose.theta)};
    me.omega = omega;
  };
  step(0.0);
  Rng rng(1);
  cam->render(w, 0, cfg.initial, rng);  // warm-up
  int k = 0;
  for (auto _ : state) {
    step(++k % 60 < 30 ? 1.0 / 30 : -1.0 / 30);  // back and forth, so the observer stays on the field
    Image img = cam->render(w, 0, cfg.initial, rng);
    benchmark::DoNotOptimize(img.rgb.data());
  }
}

// The CPU-side pieces of a field_robot frame on one rendered radiance buffer: defocus, the rotation
// smear (2 rad/s over 18 ms), three sub-frames summed and averaged (the re-rendering path), three
// sub-frames resampled from one render (TranslationBlur), and the sensor (noise, rounding).
enum class Piece { kDefocus, kSmear, kSubframes, kTranslation, kExpose };

void BM_Optics(benchmark::State& state, Piece piece) {
  CameraConfig cfg = profile_camera(Effects::kFieldRobot);
  const std::unique_ptr<PanoramicCamera> cam = make_camera(state, cfg);
  if (!cam) return;
  const MirrorProfile mirror = MirrorProfile::preset(cfg.mirror, cfg.rim_px(), cfg.mount_height);
  CameraConfig only = cfg;
  only.optical_blur_px = piece == Piece::kDefocus ? cfg.optical_blur_px : 0.0;
  only.motion_blur = piece == Piece::kSmear || piece == Piece::kSubframes || piece == Piece::kTranslation;
  Photometry ph(only, mirror, 1);
  Rng rng(1);
  ph.draw_noise_table(rng);
  // A plausible radiance buffer: a carpet-green field with bright lines every 40 px.
  std::vector<std::uint16_t>& rad = ph.radiance();
  rad.assign(static_cast<std::size_t>(cfg.width) * cfg.height * 4, 0);
  for (int y = 0; y < cfg.height; ++y)
    for (int x = 0; x < cfg.width; ++x) {
      const bool line = (x % 40) < 3 || (y % 40) < 3;
      std::uint16_t* p = &rad[(static_cast<std::size_t>(y) * cfg.width + x) * 4];
      p[0] = line ? 60000 : 5000;
      p[1] = line ? 60000 : 20000;
      p[2] = line ? 60000 : 6000;
      p[3] = 65535;
    }
  const std::vector<std::uint16_t> original = rad;
  ph.subframe() = original;
  for (auto _ : state) {
    switch (piece) {
      case Piece::kDefocus:
        state.PauseTiming();
        ph.radiance() = original;
        state.ResumeTiming();
        ph.apply_optics(0.0);
        break;
      case Piece::kSmear:
        state.PauseTiming();
        ph.radiance() = original;
        state.ResumeTiming();
        ph.apply_optics(2.0 * 0.018);
        break;
      case Piece::kSubframes:
        ph.clear_sum();
        for (int i = 0; i < 3; ++i) ph.add_subframe();
        ph.average(3);
        break;
      case Piece::kTranslation:
        // Three sub-frames at 1 m/s forward, 18 ms exposure, from one render (the floor everywhere).
        state.PauseTiming();
        ph.radiance() = original;
        ph.depth().assign(original.size() / 4, 1.0f);
        state.ResumeTiming();
        ph.translation_blur({1.0, 0.0}, {-0.006, 0.0, 0.006});
        break;
      case Piece::kExpose: {
        Image img = ph.expose(cfg.initial, 12345);
        benchmark::DoNotOptimize(img.rgb.data());
        break;
      }
    }
    benchmark::DoNotOptimize(ph.radiance().data());
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_default, "osmesa", "default")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_high, "osmesa", "high")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, osmesa_low, "osmesa", "low")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, egl_default, "egl", "default")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderFrame, egl_low, "egl", "low")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderProfile, robot, Effects::kRobot, 0.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderProfile, field_robot, Effects::kFieldRobot, 0.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderProfile, field_robot_turning, Effects::kFieldRobot, 2.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderProfile, field_robot_no_motion_blur, Effects::kNoMotionBlur, 0.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RenderProfile, field_robot_no_defocus, Effects::kNoDefocus, 0.0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Optics, defocus, Piece::kDefocus)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Optics, rotation_smear, Piece::kSmear)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Optics, three_subframes_sum, Piece::kSubframes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Optics, translation_blur, Piece::kTranslation)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Optics, expose, Piece::kExpose)->Unit(benchmark::kMillisecond)->UseRealTime();
