// The olp/1 clients' field distance (clients/cpp/omniloc_client.hpp, clients/python/omniloc_client.py)
// against omniloc's own (core/field.hpp Field::distance_to_marking, what the built-in distance map
// holds): on a 5 cm grid over every field preset's floor, penalty and centre spots included. Outside
// clients found the clients ignored the spots (up to 0.825 m off near one).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/field.hpp"
#include "omniloc_client.hpp"
#include "core/install_paths.hpp"

namespace {

using omniloc::Field;
namespace olp = omniloc_client;
namespace fs = std::filesystem;

const std::vector<std::string> kPresets = {"msl2012", "msl2007", "arena_10x8"};

// The grid of world points (metres) over the whole floor, margin included.
std::vector<std::array<double, 2>> grid(const Field& f) {
  std::vector<std::array<double, 2>> pts;
  for (double x = -f.half_floor_x(); x <= f.half_floor_x() + 1e-9; x += 0.05)
    for (double y = -f.half_floor_y(); y <= f.half_floor_y() + 1e-9; y += 0.05) pts.push_back({x, y});
  return pts;
}

olp::Field client_field(const Field& f) {
  const nlohmann::json hello = {{"type", "hello"}, {"protocol", "olp/1"}, {"field", f.markings_json()}};
  return olp::detail::parse_hello(hello).field;
}

TEST(FieldDistance, CppClientEqualsOmnilocOnEveryPresetGrid) {
  int with_spots = 0;
  for (const auto& name : kPresets) {
    const Field f = Field::preset(name);
    with_spots += !f.spots.empty();
    const olp::Field c = client_field(f);
    double worst = 0.0;
    std::size_t near_spot = 0;
    for (const auto& p : grid(f)) {
      const double ours = f.distance_to_marking({p[0], p[1]});
      worst = std::max(worst, std::fabs(c.distance_to_lines(p[0], p[1]) - ours));
      for (const auto& s : f.spots) near_spot += (Eigen::Vector2d(p[0], p[1]) - s.centre).norm() < 0.5;
    }
    EXPECT_LT(worst, 1e-9) << name;
    EXPECT_EQ(near_spot > 0, !f.spots.empty()) << name;
  }
  EXPECT_GE(with_spots, 2) << "the soccer presets have centre and penalty spots: without them the spots go untested";
}

TEST(FieldDistance, PythonClientEqualsOmnilocOnEveryPresetGrid) {
  const fs::path dir = fs::temp_directory_path() / ("omniloc_field_distance_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const auto& name : kPresets) {
    const Field f = Field::preset(name);
    const auto pts = grid(f);
    nlohmann::json in = {{"field", f.markings_json()}, {"points", pts}};
    std::ofstream(dir / "in.json") << in.dump();
    const std::string py =
        "import json,sys; sys.path.insert(0, sys.argv[1]); import omniloc_client as o; j = json.load(open(sys.argv[2]));"
        "f = o.Field.from_json(j['field']); json.dump([f.distance_to_lines(x, y) for x, y in j['points']], open(sys.argv[3], 'w'))";
    const std::string cmd = "/usr/bin/python3 -c \"" + py + "\" " + std::string(omniloc::source_dir().string()) + "/clients/python " +
                            (dir / "in.json").string() + " " + (dir / "out.json").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const auto out = nlohmann::json::parse(std::ifstream(dir / "out.json")).get<std::vector<double>>();
    ASSERT_EQ(out.size(), pts.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < pts.size(); ++i) worst = std::max(worst, std::fabs(out[i] - f.distance_to_marking({pts[i][0], pts[i][1]})));
    EXPECT_LT(worst, 1e-9) << name;
  }
  fs::remove_all(dir);
}

}  // namespace
