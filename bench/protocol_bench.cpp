// The cost of olp/1 (docs/protocol.md) per frame: one frame sent to an external client and its
// estimate read back, beside the built-in odometry_only localizer on the same observations
// (the protocol's targets on the 2-core machine: <= 0.3 ms per frame with observations only, <= 2 ms with a
// 640 x 640 image). Wall time (UseRealTime): the client's work happens in another process.
//   BM_OdometryOnlyUpdate           the built-in localizer, no protocol
//   BM_OlpRoundTrip/<client>/<img>  client 0 = a minimal C++ client (bench/olp_bench_client.cpp),
//                                   1 = the shipped Python dead-reckoning example; img 1 = with the image
#include <filesystem>

#include <benchmark/benchmark.h>

#include "core/field.hpp"
#include "core/rng.hpp"
#include "external/external_localizer.hpp"
#include "localization/odometry_only.hpp"
#include "testing/scenes.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;

namespace {

// A tracking frame's observations: 90 line points (the median of the tracking scenario) and, when
// asked, the 640 x 640 image.
Observations frame_obs(bool image) {
  const Field f = Field::preset("msl2012");
  Rng rng(1);
  Observations obs;
  obs.line_points = scenes::line_points(f, Pose2(-3.0, 1.0, 0.4), 90, rng, scenes::kBenchmarkLinePoints);
  if (image) {
    auto img = std::make_shared<Image>();
    img->width = img->height = 640;
    img->rgb.resize(640 * 640 * 3);
    for (std::size_t i = 0; i < img->rgb.size(); ++i) img->rgb[i] = static_cast<std::uint8_t>(i * 2654435761u >> 24);
    obs.image = img;
  }
  return obs;
}

Odometry step() {
  Odometry od;
  od.delta = Pose2(0.033, 0.001, 0.002);
  return od;
}

}  // namespace

static void BM_OdometryOnlyUpdate(benchmark::State& state) {
  OdometryOnlyLocalizer loc;
  loc.reset(Pose2(0, 0, 0));
  const Observations obs = frame_obs(false);
  for (auto _ : state) benchmark::DoNotOptimize(loc.update(obs, step(), std::nullopt).pose);
}
BENCHMARK(BM_OdometryOnlyUpdate)->UseRealTime();

static void BM_OlpRoundTrip(benchmark::State& state) {
  const bool python = state.range(0) == 1, image = state.range(1) == 1;
  const std::string src = omniloc::source_dir().string();
  Json command = python ? Json{std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3",
                               src + "/clients/python/examples/dead_reckoning.py"}
                        : Json{OLP_BENCH_CLIENT};
  if (!python && image) command.push_back("image");
  Json params = Json::object();
  if (python && image) params["wants_image"] = true;
  const Json spec{{"command", command}, {"params", params}};
  JsonReader r(spec, "/localizer");
  external::ExternalConfig cfg = external::ExternalConfig::from_json(r);
  external::Session s;
  s.log_dir = std::filesystem::temp_directory_path().string();
  s.robot = 90 + static_cast<int>(state.range(0) * 2 + state.range(1));
  external::ExternalLocalizer loc(cfg, s);
  if (loc.wants_image() != image) {
    state.SkipWithError("the client did not ask for the image as expected");
    return;
  }
  loc.reset(Pose2(0, 0, 0));
  const Observations obs = frame_obs(image);
  for (auto _ : state) benchmark::DoNotOptimize(loc.update(obs, step(), std::nullopt).pose);
  loc.finish();
  state.SetLabel(std::string(python ? "python" : "c++") + (image ? ", 640x640 image" : ", observations"));
}
BENCHMARK(BM_OlpRoundTrip)->Args({0, 0})->Args({0, 1})->Args({1, 0})->Args({1, 1})->UseRealTime()->Unit(benchmark::kMicrosecond);
