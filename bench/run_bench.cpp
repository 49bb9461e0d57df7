// End-to-end throughput: whole `omniloc run`s (physics, sensors, rendering, vision, localizer,
// scoring, writing results), reported as simulated camera frames per wall-clock second on one core.
// Run with LP_NUM_THREADS=1 so llvmpipe rendering stays on one core.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;

namespace {

void run_file(benchmark::State& state, const std::string& rel, double duration, const char* localizer = nullptr) {
  const std::string path = std::string(omniloc::source_dir().string()) + "/" + rel;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("missing scenario " + rel).c_str());
    return;
  }
  Json j = Json::parse(std::ifstream(path));
  j["duration"] = duration;  // a shorter run of the same scenario keeps the benchmark quick
  if (localizer) j["localizer"] = {{"type", localizer}};
  const harness::Scenario s = harness::parse_scenario(j, "bench_" + std::filesystem::path(rel).stem().string());
  harness::RunOptions o;
  o.out_dir = (std::filesystem::temp_directory_path() / ("omniloc_bench_" + s.name)).string();
  double frames = 0;
  for (auto _ : state) {
    const auto r = harness::run_scenario(s, o);
    frames += static_cast<double>(r.robots.at(0).frames);
  }
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
}

}  // namespace

static void BM_RunQuickstart(benchmark::State& s) { run_file(s, "scenarios/quickstart.json", 10.0); }
BENCHMARK(BM_RunQuickstart)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_RunCrowd(benchmark::State& s) { run_file(s, "scenarios/crowd.json", 10.0); }
BENCHMARK(BM_RunCrowd)->Unit(benchmark::kMillisecond)->UseRealTime();

// The crowd with the hybrid localizer: the observer's panorama rendered and processed every frame
// (issue target: 50 frames/s on one core).
static void BM_RunCrowdHybrid(benchmark::State& s) { run_file(s, "scenarios/crowd.json", 10.0, "hybrid"); }
BENCHMARK(BM_RunCrowdHybrid)->Unit(benchmark::kMillisecond)->UseRealTime();

static void BM_RunTracking(benchmark::State& s) { run_file(s, "scenarios/paper/tracking.json", 10.0); }
BENCHMARK(BM_RunTracking)->Unit(benchmark::kMillisecond)->UseRealTime();
