#include <gtest/gtest.h>

#include <cmath>

#include <filesystem>
#include <functional>

#include "core/atomic_file.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"

using namespace omniloc;
using namespace omniloc::harness;

namespace {
Json base() {
  return Json::parse(R"({
    "duration": 2.0,
    "robots": [
      {"id": 0, "start": [0, -2, 0], "motion": {"type": "waypoints", "speed": 1.0, "points": [[1, -2]]}},
      {"id": 1, "team": 1, "start": [3, 0, 0], "localize": false}
    ],
    "ball": {"position": [1, 1]},
    "events": [{"type": "kidnap", "t": 1.0, "pose": [2, 2, 0]}],
    "localizer": {"type": "odometry_only"}
  })");
}

std::string error_path(const Json& j) {
  try {
    parse_scenario(j, "t");
  } catch (const ConfigError& e) {
    return e.path();
  }
  return "(accepted)";
}
}  // namespace

TEST(ScenarioValidation, BaseIsValid) { EXPECT_EQ(error_path(base()), "(accepted)"); }

struct BadCase {
  const char* name;
  std::function<void(Json&)> mutate;
  const char* path;
};

TEST(ScenarioValidation, EveryErrorNamesItsJsonPath) {
  const std::vector<BadCase> cases = {
      {"misspelt top-level key", [](Json& j) { j["duraton"] = 3; }, "/duraton"},
      {"negative duration", [](Json& j) { j["duration"] = -1; }, "/duration"},
      {"string duration", [](Json& j) { j["duration"] = "long"; }, "/duration"},
      {"camera faster than physics", [](Json& j) { j["camera_rate"] = 150; j["physics_rate"] = 100; }, "/camera_rate"},
      {"unknown preset", [](Json& j) { j["field"] = "nofield"; }, "/field"},
      {"field too large", [](Json& j) { j["field"] = Json{{"length", 40}}; }, "/field/length"},
      {"unknown noise profile", [](Json& j) { j["noise_profile"] = "noisy"; }, "/noise_profile"},
      {"no robots", [](Json& j) { j["robots"] = Json::array(); }, "/robots"},
      {"robot key typo", [](Json& j) { j["robots"][0]["strat"] = {0, 0, 0}; }, "/robots/0/strat"},
      {"start outside walls", [](Json& j) { j["robots"][0]["start"] = {12, 0, 0}; }, "/robots/0/start"},
      {"start with two numbers", [](Json& j) { j["robots"][0]["start"] = {1, 0}; }, "/robots/0/start"},
      {"duplicate id", [](Json& j) { j["robots"][1]["id"] = 0; }, "/robots/1/id"},
      {"overlapping robots", [](Json& j) { j["robots"][1]["start"] = {0.2, -2, 0}; }, "/robots/1/start"},
      {"unknown motion", [](Json& j) { j["robots"][0]["motion"]["type"] = "fly"; }, "/robots/0/motion/type"},
      {"negative speed", [](Json& j) { j["robots"][0]["motion"]["speed"] = -1; }, "/robots/0/motion/speed"},
      {"bad waypoint", [](Json& j) { j["robots"][0]["motion"]["points"][0] = "x"; }, "/robots/0/motion/points/0"},
      {"odometry noise typo", [](Json& j) { j["robots"][0]["odometry"] = {{"trans_sgma", 0.1}}; }, "/robots/0/odometry/trans_sgma"},
      {"negative heading noise", [](Json& j) { j["robots"][0]["heading"] = {{"noise_sigma", -0.1}}; }, "/robots/0/heading/noise_sigma"},
      {"nobody localized", [](Json& j) { j["robots"][0]["localize"] = false; }, "/robots"},
      {"ball outside", [](Json& j) { j["ball"]["position"] = {0, 9}; }, "/ball/position"},
      {"event type", [](Json& j) { j["events"][0]["type"] = "explode"; }, "/events/0/type"},
      {"event after the end", [](Json& j) { j["events"][0]["t"] = 5.0; }, "/events/0/t"},
      {"event unknown robot", [](Json& j) { j["events"][0]["robot"] = 7; }, "/events/0/robot"},
      {"kidnap into a wall", [](Json& j) { j["events"][0]["pose"] = {9.9, 0, 0}; }, "/events/0/pose"},
      {"localizer unknown", [](Json& j) { j["localizer"]["type"] = "magic"; }, "/localizer/type"},
      {"localizer param typo", [](Json& j) { j["localizer"]["particels"] = 5; }, "/localizer/particels"},
      {"camera not an object", [](Json& j) { j["camera"] = 3; }, "/camera"},
      {"occlusion fraction > 1", [](Json& j) { j["occlusion"] = {{"fraction", 1.5}}; }, "/occlusion/fraction"},
      {"occlusion frame", [](Json& j) { j["occlusion"] = {{"fraction", 0.5}, {"frame", "camera"}}; }, "/occlusion/frame"},
      {"overlapping event sectors",
       [](Json& j) { j["events"].push_back(Json::parse(R"({"type": "occlude", "t": 0.5, "sectors": [[0, 90], [80, 20]]})")); },
       "/events/1/sectors/1"},
      {"occlude typo", [](Json& j) { j["events"].push_back(Json::parse(R"({"type": "occlude", "t": 0.5, "fracton": 0.2})")); }, "/events/1/fraction"},
      {"lights without level", [](Json& j) { j["events"].push_back(Json::parse(R"({"type": "lights", "t": 0.5})")); }, "/events/1/level"},
      {"negative lamp level", [](Json& j) { j["lighting"] = {{"level", -1}}; }, "/lighting/level"},
      {"sun patch typo", [](Json& j) { j["lighting"] = Json::parse(R"({"sun": [{"centre": [0, 0], "strenght": 2}]})"); }, "/lighting/sun/0/strenght"},
      {"lamp index out of range",
       [](Json& j) {
         j["lighting"] = Json::parse(R"({"lamp_grid": {"nx": 2, "ny": 2}})");
         j["events"].push_back(Json::parse(R"({"type": "lights", "t": 0.5, "level": 0, "lamps": [1, 4]})"));
       },
       "/events/1/lamps/1"},
      {"lamp event without lamps", [](Json& j) { j["events"].push_back(Json::parse(R"({"type": "lights", "t": 0.5, "level": 0, "lamps": [0]})")); }, "/events/1/lamps/0"},
      {"lamp index not an integer",
       [](Json& j) {
         j["lighting"] = Json::parse(R"({"lamp_grid": {"nx": 2, "ny": 2}})");
         j["events"].push_back(Json::parse(R"({"type": "lights", "t": 0.5, "level": 0, "lamps": ["left"]})"));
       },
       "/events/1/lamps/0"},
      {"lamp spread", [](Json& j) { j["lighting"] = Json::parse(R"({"lamps": [{"centre": [0, 0], "spread": 0}]})"); }, "/lighting/lamps/0/spread"},
      {"lamps and grid", [](Json& j) { j["lighting"] = Json::parse(R"({"lamps": [{"centre": [0, 0]}], "lamp_grid": {"nx": 2}})"); }, "/lighting/lamp_grid"},
      {"wall sun upside down",
       [](Json& j) { j["lighting"] = Json::parse(R"({"sun": [{"surface": "wall", "centre": [0, 7], "height": [0.5, 0.2]}]})"); },
       "/lighting/sun/0/height"},
      {"sun surface", [](Json& j) { j["lighting"] = Json::parse(R"({"sun": [{"surface": "ceiling", "centre": [0, 7]}]})"); }, "/lighting/sun/0/surface"},
      {"mark unknown robot", [](Json& j) { j["robots"][1]["motion"] = Json::parse(R"({"type": "behaviour", "kind": "mark", "target": 5})"); }, "/robots/1/motion/target"},
      {"unknown behaviour", [](Json& j) { j["robots"][1]["motion"] = Json::parse(R"({"type": "behaviour", "kind": "dance"})"); }, "/robots/1/motion/kind"},
  };
  for (const auto& c : cases) {
    Json j = base();
    c.mutate(j);
    EXPECT_EQ(error_path(j), c.path) << c.name;
  }
}

TEST(Scenario, LightingScriptInterpolatesLampsAndMovesTheSun) {
  Json j = base();
  j["lighting"] = Json::parse(R"({"level": 1.0, "sun": [{"centre": [0, 0], "velocity": [0.1, 0], "strength": 4}]})");
  j["events"] = Json::parse(R"([{"type": "lights", "t": 0.5, "level": 0.2, "transition": 1.0}])");
  j["duration"] = 3.0;
  const Scenario s = parse_scenario(j, "light");
  EXPECT_DOUBLE_EQ(s.lighting_at(0.4).level, 1.0);
  EXPECT_NEAR(s.lighting_at(1.0).level, 0.6, 1e-12);  // half way through the dimming
  EXPECT_NEAR(s.lighting_at(2.0).level, 0.2, 1e-12);
  EXPECT_NEAR(s.lighting_at(2.0).sun[0].centre.x(), 0.2, 1e-12);
}

TEST(Scenario, LampSubsetsSwitchAndDarkenTheirPartOfTheHall) {
  Json j = base();
  // 2 x 1 grid on the 18 x 12 field (floor 20 x 14): lamp 0 at x = -5, lamp 1 at x = +5.
  j["lighting"] = Json::parse(R"({"level": 1.0, "lamp_grid": {"nx": 2, "ny": 1, "spread": 3.0}, "lamp_diffuse": 0.25})");
  j["events"] = Json::parse(R"([{"type": "lights", "t": 0.5, "level": 0.0, "transition": 1.0, "lamps": [1]},
                                 {"type": "lights", "t": 2.0, "level": 0.5, "transition": 0.0}])");
  j["duration"] = 3.0;
  const Scenario s = parse_scenario(j, "lamps");
  ASSERT_EQ(s.lighting.lamps.size(), 2u);
  EXPECT_NEAR(s.lighting.lamps[0].centre.x(), -5.0, 1e-12);
  EXPECT_NEAR(s.lighting.lamps[1].centre.x(), 5.0, 1e-12);
  // All on: the normal level everywhere, whatever the lamps' layout.
  for (double x : {-9.0, -2.0, 0.0, 3.0, 9.0}) EXPECT_NEAR(s.lighting_at(0.0).at({x, 1.0}), 1.0, 1e-12);
  EXPECT_NEAR(s.lighting_at(1.0).lamps[1].state, 0.5, 1e-12);  // half way through switching off
  const sim::Lighting off = s.lighting_at(1.6);
  EXPECT_DOUBLE_EQ(off.lamps[1].state, 0.0);
  EXPECT_DOUBLE_EQ(off.lamps[0].state, 1.0);
  // Midway between the lamps: half the direct light plus the diffuse share of the mean state.
  EXPECT_NEAR(off.at({0.0, 0.0}), 0.75 * 0.5 + 0.25 * 0.5, 1e-12);
  // Under the lamp that is off: only what lamp 0's footprint reaches (exp(-100/18) of the direct part) and the diffuse light.
  const double k = std::exp(-100.0 / 18.0);
  EXPECT_NEAR(off.at({5.0, 0.0}), 0.75 * k / (1.0 + k) + 0.125, 1e-12);
  EXPECT_GT(off.at({-5.0, 0.0}), 0.8);
  // Far outside every footprint: the mean state.
  EXPECT_NEAR(off.artificial_at({1e4, 0.0}), 0.5, 1e-12);
  // A later global event scales the whole pattern.
  EXPECT_NEAR(s.lighting_at(2.5).at({0.0, 0.0}), 0.25, 1e-12);
}

// A localizer given apart from the scenario (replay --localizer, a sweep's localizers) replaces the
// scenario's own, unread, and its errors name where it was given, as a LocalizerError; the scenario's
// other errors stay plain ConfigErrors at their own paths.
TEST(ScenarioValidation, AGivenLocalizerIsReadInPlaceOfTheOwnAndNamedWhereItWasGiven) {
  Json j = base();
  j["localizer"] = Json::array({"not", "a", "localizer"});
  const LocalizerSpec mcl({{"type", "mcl"}, {"particles", 300}}, "--localizer");
  const Scenario s = parse_scenario(j, "t", "", &mcl);
  EXPECT_EQ(s.localizer.type(), "mcl");
  EXPECT_EQ(s.localizer.path, "--localizer");
  EXPECT_EQ(s.input["localizer"], mcl.json);  // what a recording of this run keeps
  EXPECT_EQ(error_path(j), "/localizer");     // without it, the own one is read

  const LocalizerSpec bad({{"type", "mcl"}, {"particles", "many"}}, "/localizers/3");
  try {
    parse_scenario(base(), "t", "", &bad);
    FAIL();
  } catch (const LocalizerError& e) {
    EXPECT_EQ(e.path(), "/localizers/3/particles");
  }
  Json other = base();
  other["duration"] = -1;
  try {
    parse_scenario(other, "t", "", &mcl);
    FAIL();
  } catch (const LocalizerError& e) {
    FAIL() << "the scenario's own error taken for the localizer's: " << e.what();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/duration");
  }
  const LocalizerSpec unknown({{"type", "nope"}}, "--localizer/0");
  EXPECT_THROW(localizer_info(unknown), LocalizerError);
}

TEST(ScenarioValidation, SyntaxErrorNamesTheFile) {
  const std::string p = (std::filesystem::temp_directory_path() / "omniloc_bad_syntax.json").string();
  write_file_atomic(p, "{\"duration\": 3,,}");
  try {
    load_scenario(p);
    FAIL();
  } catch (const ConfigError& e) {
    // The path is the JSON pointer where the parser stood (the object); the message names the file.
    EXPECT_EQ(e.path(), "");
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("parse error"), std::string::npos);
  }
}

TEST(ScenarioValidation, EffectiveConfigHasDefaults) {
  const Scenario s = parse_scenario(base(), "t");
  EXPECT_EQ(s.effective["physics_rate"], 200.0);
  EXPECT_EQ(s.effective["noise_profile"], "robot");
  EXPECT_EQ(s.effective["robots"][0]["max_speed"], 4.0);
  EXPECT_EQ(s.effective["robots"][0]["odometry"]["trans_sigma"], 0.015);
}

TEST(Determinism, SameSeedGivesByteIdenticalResults) {
  const Scenario s = parse_scenario(base(), "det");
  const auto tmp = std::filesystem::temp_directory_path() / "omniloc_det";
  std::filesystem::remove_all(tmp);
  RunOptions a, b, c;
  a.out_dir = (tmp / "a").string();
  b.out_dir = (tmp / "b").string();
  c.out_dir = (tmp / "c").string();
  c.seed = 99;
  run_scenario(s, a);
  run_scenario(s, b);
  run_scenario(s, c);
  for (const char* f : {"gt.tum", "est.tum", "summary.json", "frames.csv", "events.jsonl", "config.json"})
    EXPECT_EQ(read_file(a.out_dir + "/" + f), read_file(b.out_dir + "/" + f)) << f;
  EXPECT_NE(read_file(a.out_dir + "/est.tum"), read_file(c.out_dir + "/est.tum"));
  // Nothing half-written is left beside the results.
  for (const auto& e : std::filesystem::directory_iterator(tmp)) EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos);
}

TEST(Runner, KidnapTeleportsWithoutOdometryAndIsLogged) {
  const Scenario s = parse_scenario(base(), "kid");
  RunOptions o;
  o.out_dir = (std::filesystem::temp_directory_path() / "omniloc_kid").string();
  const RunResult r = run_scenario(s, o);
  const std::string ev = read_file(o.out_dir + "/events.jsonl");
  EXPECT_NE(ev.find("\"kidnap\""), std::string::npos);
  // Dead reckoning cannot know about the teleport: the final error is about the jump (~4.3 m).
  EXPECT_GT(r.robots[0].all.pos_max_m, 3.5);
}

// Validation checks a built-in localizer's parameters without building it (no distance map, no
// association grid): it must refuse exactly what building refuses, with the same words.
TEST(LocalizerCheck, RefusesWhatBuildingRefusesWithTheSameError) {
  const Field field = Field::preset("msl2012");
  LocalizerContext ctx;
  ctx.field = &field;
  const auto error_of = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const LocalizerError& e) {
      return e.what();
    }
    return "";
  };
  int compared = 0;
  for (const auto& info : localizers()) {
    if (info.type == "external") continue;  // building it needs a run (its client process)
    std::vector<Json> docs = {Json{{"type", info.type}}, Json{{"type", info.type}, {"no_such_key", 1}}};
    const Json schema = info.schema();
    for (const auto& [key, prop] : schema.items()) {
      docs.push_back(Json{{"type", info.type}, {key, "a string"}});
      if (prop.contains("minimum")) docs.push_back(Json{{"type", info.type}, {key, prop["minimum"].get<double>() - 1.0}});
    }
    for (const Json& j : docs) {
      const LocalizerSpec spec(j, "/localizer");
      const std::string checked = error_of([&] { check_localizer(spec, ctx); });
      const std::string built = error_of([&] { (void)make_localizer(spec, ctx); });
      EXPECT_EQ(checked, built) << j.dump();
      if (j.size() == 1) {
        EXPECT_EQ(checked, "") << j.dump();  // the defaults are valid
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 50);
}
