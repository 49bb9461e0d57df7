// How accurate the line points are that olp/1 clients get (docs/protocol.md, `frame.line_points`):
// each point of the built-in vision, placed in the world with the pose the camera saw it from (the
// simulator's truth, for scoring only), against the nearest marking's centre line (a spot's rim).
// The printed table is the one docs/protocol.md quotes; the bounds below catch a vision that drifts
// far from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "harness/camera_perception.hpp"
#include "harness/perception.hpp"
#include "harness/scenario.hpp"
#include "harness/simulation.hpp"
#include "core/install_paths.hpp"

namespace omniloc {
namespace {

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

TEST(LinePointAccuracy, DistanceToTheNearestLineCentreByRange) {
  harness::Scenario sc = harness::load_scenario(std::string(omniloc::source_dir().string()) + "/scenarios/paper/tracking.json");
  const std::uint64_t seed = 1;
  harness::Simulation sim(sc, seed);
  const auto perception = harness::make_perception(sc, true, seed);
  const int id = sc.localized_robots().front();
  // Range bands (metres from the robot): where the mirror's resolution halves and halves again.
  const std::vector<double> edges = {0.0, 1.5, 3.0, 5.0, 7.5};  // the scan lines stop at 7.5 m
  std::vector<std::vector<double>> off(edges.size() - 1);
  // Every 3rd frame of the first 20 s (200 frames): the whole first lap of the tracking path.
  for (long long k = 0; k <= 600; ++k) {
    sim.advance_to(static_cast<double>(k) / sc.camera_rate);
    const sim::WorldState now = sim.state();
    const sim::WorldState seen = sim.camera_view(now);
    const harness::PerceptionOutput po = perception->observe(seen, id, now.t, sim.conditions(id, now));
    sim.set_paused(id, po.stop_robot);
    if (k % 3 != 0) continue;
    const Pose2 pose = seen.robot(id)->pose;
    for (const auto& p : po.obs.line_points) {
      const double r = p.norm();
      for (std::size_t b = 0; b + 1 < edges.size(); ++b)
        if (r >= edges[b] && r < edges[b + 1]) off[b].push_back(sc.field.distance_to_marking(pose.transform(p)));
    }
  }
  std::printf("line points of scenarios/paper/tracking.json (robot profile), seed 1, every 3rd frame of 0-20 s:\n"
              "| range (m) | points | median (cm) | p90 (cm) |\n|---|---|---|---|\n");
  std::vector<double> medians;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
    ASSERT_GT(off[b].size(), 100u) << "band " << edges[b];
    medians.push_back(100 * quantile(off[b], 0.5));
    std::printf("| %.1f-%.1f | %zu | %.1f | %.1f |\n", edges[b], edges[b + 1], off[b].size(), medians.back(), 100 * quantile(off[b], 0.9));
  }
  // A point lies within half a painted line (6.25 cm) of the centre when the vision and the map are
  // right; beyond 5 m a pixel spans 10-20 cm of floor. Bounds: the near bands' medians within half a
  // line width plus the pose jitter, the far band's within a pixel's footprint.
  EXPECT_LT(medians[0], 6.0);
  EXPECT_LT(medians[1], 6.0);
  EXPECT_LT(medians[2], 12.0);
  EXPECT_LT(medians[3], 25.0);
}

}  // namespace
}  // namespace omniloc
