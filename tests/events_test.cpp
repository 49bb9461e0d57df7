// Scenario events (harness/events.*): parsing of every kind, errors naming their JSON path, and what
// each kind does to the Simulation and writes to events.jsonl.
#include <gtest/gtest.h>

#include <cmath>

#include "harness/events.hpp"
#include "harness/scenario.hpp"
#include "harness/simulation.hpp"

using namespace omniloc;
using namespace omniloc::harness;

namespace {

Json scenario_with(const Json& events) {
  Json j = Json::parse(R"({
    "duration": 3.0, "noise_profile": "ideal",
    "robots": [
      {"id": 0, "start": [0, -2, 0]},
      {"id": 3, "start": [3, 0, 0], "localize": false}
    ],
    "lighting": {"level": 1.0, "lamps": [{"centre": [-4, 0]}, {"centre": [4, 0]}]},
    "localizer": {"type": "odometry_only"}
  })");
  j["events"] = events;
  return j;
}

std::string error_path(const Json& events) {
  try {
    parse_scenario(scenario_with(events), "t");
  } catch (const ConfigError& e) {
    return e.path();
  }
  return "(accepted)";
}

}  // namespace

TEST(Events, TypeNamesFollowTheVariant) {
  EXPECT_EQ(event_type_names(), (std::vector<std::string>{"teleport", "kidnap", "cover", "occlude", "lights", "slip"}));
}

TEST(Events, EveryKindParsesWithItsDefaults) {
  const Scenario s = parse_scenario(scenario_with(Json::parse(R"([
      {"type": "lights", "t": 2.5, "level": 0.0, "lamps": [1]},
      {"type": "teleport", "t": 0.5, "robot": 3, "pose": [1, 1, 0.5]},
      {"type": "kidnap", "t": 1.0, "pose": "random"},
      {"type": "cover", "t": 1.5},
      {"type": "occlude", "t": 2.0, "fraction": 0.25, "sectors": 2}
    ])")), "t");
  ASSERT_EQ(s.events.size(), 5u);
  // Sorted by time; the robot defaults to the first localized one.
  EXPECT_EQ(s.events[0].type(), "teleport");
  EXPECT_EQ(s.events[0].robot, 3);
  EXPECT_DOUBLE_EQ(s.events[0].as<Teleport>()->pose.theta, 0.5);
  ASSERT_NE(s.events[1].as<Kidnap>(), nullptr);
  EXPECT_TRUE(s.events[1].as<Kidnap>()->random_pose);
  EXPECT_DOUBLE_EQ(s.events[1].duration(), 2.0);
  EXPECT_EQ(s.events[1].robot, 0);
  EXPECT_DOUBLE_EQ(s.events[2].duration(), 1.0);  // cover
  EXPECT_TRUE(s.events[2].disrupts_tracking());
  EXPECT_FALSE(s.events[0].disrupts_tracking());
  EXPECT_NEAR(s.events[3].as<Occlude>()->mask.fraction(), 0.25, 1e-12);
  const Lights* l = s.events[4].as<Lights>();
  ASSERT_NE(l, nullptr);
  EXPECT_DOUBLE_EQ(l->transition, 0.5);
  EXPECT_EQ(l->lamps, std::vector<int>{1});
  EXPECT_DOUBLE_EQ(s.events[4].duration(), 0.0);
}

TEST(Events, ErrorsNameTheirJsonPath) {
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "explode", "t": 1}])")), "/events/0/type");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "cover", "t": 9}])")), "/events/0/t");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "cover", "t": 1, "robot": 7}])")), "/events/0/robot");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "cover", "t": 1}, {"type": "teleport", "t": 1, "pose": [30, 0, 0]}])")), "/events/1/pose");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "kidnap", "t": 1, "pose": "anywhere"}])")), "/events/0/pose");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "cover", "t": 1, "level": 2}])")), "/events/0/level");  // a key of another kind
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "lights", "t": 1, "level": 0, "lamps": [2]}])")), "/events/0/lamps/0");
  EXPECT_EQ(error_path(Json::parse(R"([{"type": "occlude", "t": 1, "fraction": 1.5}])")), "/events/0/fraction");
}

TEST(Events, ApplyingActsOnTheSimulationAndLogsTheRecord) {
  const Scenario s = parse_scenario(scenario_with(Json::parse(R"([
      {"type": "teleport", "t": 0.5, "robot": 3, "pose": [1, 1, 0.5]},
      {"type": "kidnap", "t": 1.0, "pose": [-2, 1, 1.0], "duration": 0.5},
      {"type": "occlude", "t": 2.0, "duration": 0.5, "sectors": [[0, 90]]},
      {"type": "lights", "t": 2.5, "level": 0.0, "lamps": [1], "transition": 0.0}
    ])")), "t");
  EventLog log;
  Simulation sim(s, 1, &log);
  sim.advance_to(0.6);
  EXPECT_NEAR(sim.state().robot(3)->pose.x, 1.0, 1e-6);
  EXPECT_NEAR(sim.state().robot(3)->pose.theta, 0.5, 1e-6);
  sim.advance_to(1.2);
  sim::WorldState now = sim.state();
  EXPECT_NEAR(now.robot(0)->pose.x, -2.0, 1e-6);
  EXPECT_TRUE(sim.conditions(0, now).covered);
  EXPECT_FALSE(sim.conditions(3, now).covered);
  sim.advance_to(1.6);
  now = sim.state();
  EXPECT_FALSE(sim.conditions(0, now).covered);  // uncovered after the kidnap's 0.5 s
  sim.advance_to(2.2);
  now = sim.state();
  ASSERT_EQ(sim.conditions(0, now).occlusion.size(), 1u);
  EXPECT_NEAR(sim.conditions(0, now).occlusion[0].width, kPi / 2, 1e-12);
  sim.advance_to(2.6);
  now = sim.state();
  EXPECT_TRUE(sim.conditions(0, now).occlusion.empty());
  EXPECT_DOUBLE_EQ(now.lighting.lamps[1].state, 0.0);
  EXPECT_DOUBLE_EQ(now.lighting.lamps[0].state, 1.0);
  // One record per event, at the time it was applied (the first physics step at or after its t).
  const std::string& text = log.text();
  std::vector<Json> records;
  for (std::size_t a = 0, b; (b = text.find('\n', a)) != std::string::npos; a = b + 1) records.push_back(Json::parse(text.substr(a, b - a)));
  ASSERT_EQ(records.size(), 4u);
  EXPECT_EQ(records[0]["type"], "teleport");
  EXPECT_EQ(records[0]["robot"], 3);
  EXPECT_EQ(records[0]["pose"], Json::array({1.0, 1.0, 0.5}));
  EXPECT_EQ(records[1]["type"], "kidnap");
  EXPECT_DOUBLE_EQ(records[1]["duration"].get<double>(), 0.5);
  EXPECT_NEAR(records[1]["t"].get<double>(), 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(records[2]["fraction"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(records[3]["level"].get<double>(), 0.0);
}

TEST(Events, RandomTargetsComeFromTheRunSeedInEventOrder) {
  const Scenario s = parse_scenario(scenario_with(Json::parse(R"([
      {"type": "teleport", "t": 0.5, "pose": "random"},
      {"type": "teleport", "t": 1.0, "robot": 3, "pose": "random"}
    ])")), "t");
  auto targets = [&](std::uint64_t seed) {
    Simulation sim(s, seed);
    sim.advance_to(0.6);
    const Pose2 a = sim.state().robot(0)->pose;
    sim.advance_to(1.1);
    return std::make_pair(a, sim.state().robot(3)->pose);
  };
  const auto [a1, b1] = targets(1);
  const auto [a2, b2] = targets(1);
  const auto [a3, b3] = targets(2);
  EXPECT_EQ(a1.x, a2.x);
  EXPECT_EQ(b1.y, b2.y);
  EXPECT_NE(a1.x, a3.x);
  // 0.5 m inside the lines of the 18 x 12 m field.
  for (const Pose2& p : {a1, b1, a3, b3}) {
    EXPECT_LE(std::fabs(p.x), 8.5 + 1e-9);
    EXPECT_LE(std::fabs(p.y), 5.5 + 1e-9);
  }
}

TEST(Events, SlipScalesTheOdometryForItsDuration) {
  // Exact sensors (ideal profile), the robot driving straight at 1 m/s: odometry = wheel motion.
  Json j = scenario_with(Json::array());
  j["robots"][0]["motion"] = Json::parse(R"({"type": "constant", "velocity": [1.0, 0.0]})");
  const Scenario plain = parse_scenario(j, "t");
  j["events"] = Json::parse(R"([{"type": "slip", "t": 1.0, "duration": 0.5, "scale": 1.5}])");
  const Scenario slipping = parse_scenario(j, "t");
  EXPECT_DOUBLE_EQ(slipping.events[0].duration(), 0.5);
  auto odometry = [](const Scenario& s) {
    Simulation sim(s, 1);
    std::vector<double> dx;
    for (double t : {1.0, 1.5, 2.0}) {
      sim.advance_to(t);
      dx.push_back(sim.read_sensors(0, sim.state()).odometry.delta.x);
    }
    return dx;
  };
  const auto a = odometry(plain), b = odometry(slipping);
  EXPECT_DOUBLE_EQ(b[0], a[0]);             // before the slip
  EXPECT_NEAR(b[1], 1.5 * a[1], 1e-12);     // during it: 1.5 x the wheel motion
  EXPECT_NEAR(a[1], 0.5, 0.01);
  EXPECT_DOUBLE_EQ(b[2], a[2]);             // after it
}
