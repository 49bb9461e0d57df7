#include <gtest/gtest.h>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "sim/occlusion.hpp"

using namespace omniloc;
using namespace omniloc::sim;

TEST(Occlusion, FractionAndPaintedArea) {
  const OcclusionMask m = OcclusionMask::from_json(Json::parse(R"({"fraction": 0.25, "sectors": 2})"), "/occlusion");
  ASSERT_EQ(m.sectors.size(), 2u);
  EXPECT_NEAR(m.fraction(), 0.25, 1e-12);
  Image img;
  img.width = img.height = 201;
  img.rgb.assign(201 * 201 * 3, 200);
  paint_sectors(img, {100.5, 100.5}, m.sectors);
  int black = 0, inside = 0;
  for (int v = 0; v < 201; ++v)
    for (int u = 0; u < 201; ++u) {
      const double du = u + 0.5 - 100.5, dv = v + 0.5 - 100.5;
      if (du * du + dv * dv > 100 * 100) continue;
      ++inside;
      black += img.row(v)[3 * u] == 0;
    }
  EXPECT_NEAR(static_cast<double>(black) / inside, 0.25, 0.01);
}

TEST(Occlusion, BearingConventionForwardIsUp) {
  // One 20-degree sector centred straight ahead must blacken the pixel above the centre only.
  OcclusionMask m = OcclusionMask::from_json(Json::parse(R"({"sectors": [[-10, 20]]})"), "/o");
  Image img;
  img.width = img.height = 101;
  img.rgb.assign(101 * 101 * 3, 255);
  paint_sectors(img, {50.5, 50.5}, m.sectors);
  EXPECT_EQ(img.row(10)[3 * 50], 0);    // ahead (up)
  EXPECT_EQ(img.row(90)[3 * 50], 255);  // behind
  EXPECT_EQ(img.row(50)[3 * 10], 255);  // left
  // World-fixed sector: a robot turned by +90 deg sees a world bearing of 0 at its right (-90).
  m.world_fixed = true;
  const auto rf = m.robot_frame(kPi / 2);
  EXPECT_NEAR(rf[0].start, wrap_angle_positive(deg2rad(-10) - kPi / 2), 1e-12);
}

TEST(Occlusion, BadInputNamesThePath) {
  auto path_of = [](const char* s) {
    try {
      OcclusionMask::from_json(Json::parse(s), "/events/2");
    } catch (const ConfigError& e) {
      return e.path();
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(path_of(R"({"fraction": 1.5})"), "/events/2/fraction");
  EXPECT_EQ(path_of(R"({"fraction": -0.1})"), "/events/2/fraction");
  EXPECT_EQ(path_of(R"({"sectors": [[0, 90], [45, 30]]})"), "/events/2/sectors/1");
  EXPECT_EQ(path_of(R"({"sectors": [[0, 0]]})"), "/events/2/sectors/0");
  EXPECT_EQ(path_of(R"({"sectors": [[350, 20], [5, 10]]})"), "/events/2/sectors/1");
  EXPECT_EQ(path_of(R"({"sectors": [[0, 90], [90, 90]]})"), "(accepted)");
}
