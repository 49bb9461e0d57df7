// `omniloc render --t` shows exactly the frame the run saw (issue 21): the run's simulation and
// perception are replayed, so exposure control's settings and pauses, the camera latency and the
// camera's noise stream agree with the frames `omniloc run --frames` saves.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "core/atomic_file.hpp"
#include "harness/render_frame.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"

using namespace omniloc;
using namespace omniloc::harness;
namespace fs = std::filesystem;

TEST(RenderFrame, ShowsTheFrameTheRunSaw) {
  // The light drops at 0.5 s; the entropy search then pauses the robot and changes exposure and gain.
  const Scenario s = parse_scenario(Json::parse(R"({
    "seed": 5, "duration": 3.0, "noise_profile": "robot",
    "robots": [{"id": 0, "start": [-3.0, -2.0, 0.3], "motion": {"type": "waypoints", "speed": 1.5, "points": [[3.0, -2.0], [3.0, 2.0]]}}],
    "localizer": {"type": "matching"},
    "events": [{"type": "lights", "t": 0.5, "level": 0.4, "transition": 0.2}],
    "vision": {"exposure_control": {"enabled": true, "search_at_start": false}}
  })"), "render_match");
  const fs::path tmp = fs::temp_directory_path() / "omniloc_render_frame_test";
  fs::remove_all(tmp);
  fs::create_directories(tmp / "frames");
  RunOptions o;
  o.out_dir = (tmp / "run").string();
  o.frames_dir = (tmp / "frames").string();
  o.frames_every = 15;
  run_scenario(s, o);
  // The replay has something to reproduce: the run paused the robot and left the initial settings.
  const std::string events = read_file(o.out_dir + "/events.jsonl");
  EXPECT_NE(events.find("\"type\":\"pause\""), std::string::npos);
  EXPECT_NE(events.find("search_end"), std::string::npos);
  for (int k : {0, 45, 75}) {
    char name[32];
    std::snprintf(name, sizeof name, "r0_%06d.png", k);  // as the run names its frames
    const std::string png = (tmp / ("render_" + std::to_string(k) + ".png")).string();
    render_to_png(s, k / 30.0, 0, s.seed, false, png);
    EXPECT_EQ(read_file(png), read_file((tmp / "frames" / name).string())) << "frame " << k;
  }
  // Another seed is another run: its frame differs.
  const std::string other = (tmp / "render_seed6.png").string();
  render_to_png(s, 75 / 30.0, 0, 6, false, other);
  EXPECT_NE(read_file(other), read_file((tmp / "frames" / "r0_000075.png").string()));
  fs::remove_all(tmp);
}
