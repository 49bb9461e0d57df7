// Fixed-work workloads for instruction counting (scripts/icount.sh): each runs a set number of
// iterations of one stage on fixed inputs, and only that loop is counted: setup (field maps,
// calibration, colour tables, the rendered frame) runs outside CALLGRIND_START/STOP_INSTRUMENTATION.
// Instruction counts under callgrind do not depend on what else the machine is doing, so CI can
// gate on a few per cent where wall-clock timings on a shared VM drift by 1.5x.
//
// usage: icount WORKLOAD [--iterations N]     icount --list     icount --prepare (fill caches natively)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else  // without valgrind's header (Debian: valgrind) the program still runs, counting nothing
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>

#include "core/field.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "harness/vision_setup.hpp"
#include "localization/field_map.hpp"
#include "localization/grid_global.hpp"
#include "localization/landmarks/landmark_solvers.hpp"
#include "localization/matching.hpp"
#include "localization/mcl.hpp"
#include "localization/modern/ukf_mh.hpp"
#include "localization/vision/blobs.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"
#include "core/install_paths.hpp"

using namespace omniloc;

namespace {

// A workload: `setup` (not counted) returns the counted body; the body returns a checksum so the
// compiler cannot drop the work.
struct Workload {
  int iterations;
  std::string what;
  std::function<std::function<double()>()> setup;
  /// The body itself fills caches (the scenario's calibration, colour table and distance map), so
  /// --prepare runs it once natively; otherwise a cold cache (a clean CI clone) would be counted.
  bool prepare_runs_body = false;
};

// A rendered frame of `field_name` seen from `pose`, with the cached calibration and colour table.
struct Frame {
  sim::CameraConfig cfg;
  Field field;
  CalibrationMap map;
  ColourTable table;
  Image image;
};

Frame rendered(const std::string& field_name, const Pose2& pose) {
  const sim::CameraConfig cfg;
  const Field field = Field::preset(field_name);
  Frame f{cfg, field, harness::calibration_for(cfg, "auto", 1), harness::colour_table_for(cfg, field, "auto", 1), {}};
  sim::PanoramicCamera cam(f.cfg, f.field);
  sim::WorldState w;
  w.has_ball = false;
  sim::RobotState me;
  me.pose = pose;
  w.robots.push_back(me);
  Rng rng(1);
  f.image = cam.render(w, 0, f.cfg.initial, rng);
  return f;
}

template <typename Solver>
Workload closed_form(Solver solve, const char* what) {
  return {1024, what, [solve] {
            const auto& cs = scenes::landmark_configs(3, 0.0);
            auto i = std::make_shared<std::size_t>(0);
            return std::function<double()>([&cs, i, solve] {
              const auto f = solve(std::span<const landmarks::BearingObs>(cs[(*i)++ % cs.size()]));
              return f.pose.x + f.pose.theta;
            });
          }};
}

std::map<std::string, Workload> workloads() {
  std::map<std::string, Workload> w;
  w["matching"] = {200, "matching update (RPROP + Kalman), 200 line points, warm start 3 cm off", [] {
                     auto f = std::make_shared<Field>(Field::preset("msl2012"));
                     auto loc = std::make_shared<MatchingLocalizer>(*f, MatchingParams{}, "");
                     Rng rng(1);
                     const Pose2 truth(-3.0, 1.0, 0.4);
                     auto obs = std::make_shared<Observations>();
                     obs->line_points = scenes::line_points(*f, truth, 200, rng, scenes::kBenchmarkLinePoints);
                     return std::function<double()>([f, loc, obs, truth] {
                       loc->reset(Pose2(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.01));
                       return loc->update(*obs, Odometry{}, std::nullopt).pose.x;
                     });
                   }};
  w["ukf_mh"] = {200, "ukf_mh tracking frame (predict, compass, 100 of 200 line points associated and updated twice with the tilt marginalised), alternative-pose rounds off", [] {
                   auto f = std::make_shared<Field>(Field::preset("msl2012"));
                   modern::UkfMhParams p;
                   p.alt_period = 1e9;
                   // As a run of the robot profile builds it: the camera's declared tilt and height.
                   p.tilt_sd = 0.3 * kPi / 180.0;
                   p.mount_height = 0.75;
                   auto loc = std::make_shared<modern::UkfMhLocalizer>(*f, p, 1, "");
                   Rng rng(1);
                   const Pose2 truth(-3.0, 1.0, 0.4);
                   auto obs = std::make_shared<Observations>();
                   obs->line_points = scenes::line_points(*f, truth, 200, rng, scenes::kBenchmarkLinePoints);
                   loc->reset(truth);
                   auto k = std::make_shared<int>(0);
                   return std::function<double()>([f, loc, obs, k, truth] {
                     obs->t += 1.0 / 30.0;
                     const Odometry odo{obs->t, Pose2(((*k)++ & 1) ? 0.03 : -0.03, 0.0, 0.0)};
                     return loc->update(*obs, odo, truth.theta).pose.x;
                   });
                 }};
  w["fieldmap_lookup"] = {100000, "field distance map lookup with gradient (5 cm cells)", [] {
                            auto m = std::make_shared<FieldMap>(Field::preset("msl2012"), 0.05);
                            auto q = std::make_shared<std::vector<Eigen::Vector2d>>();
                            Rng rng(2);
                            for (int i = 0; i < 1024; ++i) q->emplace_back(rng.uniform(-9, 9), rng.uniform(-6, 6));
                            auto i = std::make_shared<std::size_t>(0);
                            return std::function<double()>([m, q, i] {
                              Eigen::Vector2d g;
                              return m->distance((*q)[(*i)++ & 1023], &g) + g.x();
                            });
                          }};
  w["mcl_update"] = {20, "MCL update, 600 particles, 200 line points", [] {
                       auto f = std::make_shared<Field>(Field::preset("msl2012"));
                       auto mcl = std::make_shared<McLLocalizer>(*f, McLParams{}, 1, "");
                       Rng rng(3);
                       const Pose2 truth(2.0, -1.0, 0.7);
                       auto obs = std::make_shared<Observations>();
                       obs->line_points = scenes::line_points(*f, truth, 200, rng, scenes::kBenchmarkLinePoints);
                       mcl->reset(std::nullopt);
                       return std::function<double()>([f, mcl, obs, truth] {
                         Odometry odo;
                         odo.delta = Pose2(0.03, 0.0, 0.01);
                         return mcl->update(*obs, odo, truth.theta).pose.x;
                       });
                     }};
  w["grid_global"] = {2, "grid global localisation attempt (paper 000), every pass", [] {
                        auto f = std::make_shared<Field>(Field::preset("msl2012"));
                        auto map = std::make_shared<FieldMap>(*f, 0.05, "");
                        Rng rng(5);
                        const Pose2 truth(-3.2, 2.1, -0.4);
                        auto pts = std::make_shared<std::vector<Eigen::Vector2d>>(scenes::line_points(*f, truth, 200, rng, scenes::kBenchmarkLinePoints));
                        return std::function<double()>([f, map, pts, truth] {
                          GridGlobalParams p;
                          p.accept_error = 0.0;
                          const auto r = grid_search(*f, *map, *pts, truth.theta, p);
                          return r.candidates[static_cast<std::size_t>(r.chosen)].error;
                        });
                      }};
  w["closed_total_like"] = closed_form(landmarks::total_like, "ToTal-like three-beacon solve");
  w["closed_three_point"] = closed_form(landmarks::three_point_004, "three-point solve (paper 004)");
  w["closed_two_circle"] = closed_form(landmarks::two_circle_004, "two-circle solve (paper 004)");
  w["closed_circle_intersection"] = closed_form(landmarks::circle_intersection_003, "circle-intersection solve (paper 003)");
  w["line_points"] = {20, "line-point extraction (colour table, 72 scan lines, map) on a 640 x 640 frame", [] {
                        auto fr = std::make_shared<Frame>(rendered("msl2012", Pose2(-4.0, -1.0, 0.3)));
                        auto det = std::make_shared<LineDetector>(ScanLineParams{}, fr->map, fr->table);
                        return std::function<double()>([fr, det] { return static_cast<double>(det->detect(fr->image).points.size()); });
                      }};
  w["blob_detection"] = {20, "blob detection on a 640 x 640 frame of the cube arena", [] {
                           auto fr = std::make_shared<Frame>(rendered("arena_10x8", Pose2(1.0, 0.5, 0.4)));
                           auto det = std::make_shared<BlobDetector>(BlobParams{}, fr->map, fr->table);
                           return std::function<double()>([fr, det] { return static_cast<double>(det->detect(fr->image).size()); });
                         }};
  w["end_to_end"] = {1, "30 frames of the tracking scenario: physics, rendering (llvmpipe), vision, matching, scoring, writing", [] {
                       Json j = Json::parse(std::ifstream(std::string(omniloc::source_dir().string()) + "/scenarios/paper/tracking.json"));
                       j["duration"] = 29.0 / 30.0;  // frames at 0 .. 29/30 s: 30 frames
                       auto s = std::make_shared<harness::Scenario>(harness::parse_scenario(j, "icount_tracking"));
                       auto o = std::make_shared<harness::RunOptions>();
                       o->out_dir = (std::filesystem::temp_directory_path() / "omniloc_icount_end_to_end").string();
                       return std::function<double()>([s, o] { return static_cast<double>(harness::run_scenario(*s, *o).robots.at(0).frames); });
                     },
                     true};
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  const auto all = workloads();
  const std::string name = argc > 1 ? argv[1] : "";
  if (name == "--list") {
    for (const auto& [n, w] : all) std::printf("%-28s %7d  %s\n", n.c_str(), w.iterations, w.what.c_str());
    return 0;
  }
  if (name == "--prepare") {  // natively: calibration maps, colour tables and distance maps into the caches
    for (const auto& [n, w] : all) {
      auto body = w.setup();
      if (w.prepare_runs_body) body();
    }
    return 0;
  }
  const auto it = all.find(name);
  if (it == all.end()) {
    std::fprintf(stderr, "usage: icount WORKLOAD [--iterations N] | --list | --prepare (unknown workload \"%s\")\n", name.c_str());
    return 2;
  }
  int iterations = it->second.iterations;
  if (argc == 4 && std::string(argv[2]) == "--iterations") {
    char* end = nullptr;
    const long v = std::strtol(argv[3], &end, 10);
    if (!end || *end || v < 1 || v > 100000000) {
      std::fprintf(stderr, "--iterations needs an integer in [1, 1e8], got \"%s\"\n", argv[3]);
      return 2;
    }
    iterations = static_cast<int>(v);
  } else if (argc != 2) {
    std::fprintf(stderr, "usage: icount WORKLOAD [--iterations N]\n");
    return 2;
  }
  auto body = it->second.setup();
  double checksum = 0;
  CALLGRIND_START_INSTRUMENTATION;
  for (int k = 0; k < iterations; ++k) checksum += body();
  CALLGRIND_STOP_INSTRUMENTATION;
  std::printf("%s %d %.17g\n", name.c_str(), iterations, checksum);
  return 0;
}
