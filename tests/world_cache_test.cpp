// The world cache (harness/cache/world_cache.hpp, docs/recording.md section 9): what the key holds, that a
// run from the cache writes the live run's files, that a damaged entry is redrawn and never used,
// and that pruning removes the least recently used entries but never one in use.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/install_paths.hpp"
#include "harness/cache/world_cache.hpp"

using namespace omniloc;
using namespace omniloc::harness;
namespace fs = std::filesystem;

namespace {

Json tracking_json(double duration) {
  std::ifstream in(source_dir() / "scenarios/paper/tracking.json");
  Json j = Json::parse(in);
  j["duration"] = duration;
  return j;
}

Scenario scenario(const Json& j) { return parse_scenario(j, "world_cache_test"); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class WorldCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("omniloc_world_cache_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  WorldCache cache(std::uint64_t max_bytes = 0) {
    WorldCacheOptions o;
    o.dir = (dir_ / "cache").string();
    o.max_bytes = max_bytes;
    return WorldCache(o);
  }
  std::size_t entries() const {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir_ / "cache"))
      if (e.path().filename().string()[0] != '.') ++n;
    return n;
  }
  fs::path dir_;
};

}  // namespace

TEST(WorldKey, HoldsWhatDrawsTheWorldAndNothingElse) {
  const Json base = tracking_json(1.0);
  const std::string k = world_key(scenario(base), 1, false);
  EXPECT_EQ(k.size(), 32u);
  EXPECT_EQ(k, world_key(scenario(base), 1, false));
  // What changes the frames changes the key.
  EXPECT_NE(k, world_key(scenario(base), 2, false));
  EXPECT_NE(k, world_key(scenario(base), 1, true));
  Json j = base;
  j["duration"] = 1.5;
  EXPECT_NE(k, world_key(scenario(j), 1, false));
  j = base;
  j["noise_profile"] = "ideal";
  EXPECT_NE(k, world_key(scenario(j), 1, false));
  j = base;
  j["camera"]["read_noise"] = 2.0;
  EXPECT_NE(k, world_key(scenario(j), 1, false));
  j = base;
  j["robots"][0]["start"][0] = j["robots"][0]["start"][0].get<double>() + 0.01;
  EXPECT_NE(k, world_key(scenario(j), 1, false));
  // What does not: the localizer, the names, the scoring thresholds.
  j = base;
  j["localizer"] = {{"type", "mcl"}, {"particles", 300}};
  j["name"] = "another_name";
  j["description"] = "another description";
  j["scoring"] = {{"recall", Json::array({Json{{"position_m", 0.2}, {"heading_deg", 15.0}}})}};
  EXPECT_EQ(k, world_key(parse_scenario(j, "x"), 1, false));
}

TEST(WorldCacheSizes, ParseAndRefuse) {
  EXPECT_EQ(parse_byte_size("0", "x"), 0u);
  EXPECT_EQ(parse_byte_size("1048576", "x"), 1048576u);
  EXPECT_EQ(parse_byte_size("500M", "x"), 500ULL << 20);
  EXPECT_EQ(parse_byte_size("20G", "x"), 20ULL << 30);
  EXPECT_EQ(parse_byte_size("1.5GiB", "x"), 3ULL << 29);
  for (const char* bad : {"", "-1", "12Q", "G", "1e30"}) EXPECT_THROW(parse_byte_size(bad, "--max-size"), ConfigError) << bad;
}

TEST_F(WorldCacheTest, RunsFromTheCacheWriteTheLiveRunsFiles) {
  Json j = tracking_json(1.0);
  j["localizer"] = {{"type", "matching"}};
  const Scenario sc = scenario(j);
  WorldCache c = cache();
  RunOptions live, first, second;
  live.out_dir = (dir_ / "live").string();
  first.out_dir = (dir_ / "first").string();
  second.out_dir = (dir_ / "second").string();
  run_scenario(sc, live);
  const RunResult a = run_with_world_cache(sc, first, c);
  EXPECT_EQ(entries(), 1u);
  // Another localizer and another name: the same world, replayed.
  Json j2 = j;
  j2["localizer"] = {{"type", "hybrid"}};
  j2["name"] = "renamed";
  const RunResult b = run_with_world_cache(scenario(j2), second, c);
  EXPECT_EQ(entries(), 1u);
  RunOptions live2;
  live2.out_dir = (dir_ / "live2").string();
  run_scenario(scenario(j2), live2);
  for (const char* f : {"est.tum", "gt.tum", "frames.csv", "events.jsonl", "config.json", "field.json"}) {
    EXPECT_EQ(slurp(dir_ / "live" / f), slurp(dir_ / "first" / f)) << f;
    EXPECT_EQ(slurp(dir_ / "live2" / f), slurp(dir_ / "second" / f)) << f;
  }
  const std::string key = world_key(sc, sc.seed, false);
  EXPECT_EQ(a.summary["omniloc"]["world_cache"], key);
  EXPECT_EQ(b.summary["omniloc"]["world_cache"], key);
  // A localizer without vision runs live, and says why.
  Json j3 = j;
  j3["localizer"] = {{"type", "odometry_only"}};
  EXPECT_NE(world_cache_ineligible(scenario(j3), RunOptions{}), "");
  RunOptions o3;
  o3.out_dir = (dir_ / "odo").string();
  EXPECT_FALSE(run_with_world_cache(scenario(j3), o3, c).summary["omniloc"].contains("world_cache"));
}

// A GPU's pixels depend on the machine: an "egl" run draws live whether the file asks for it or
// OMNILOC_GL_BACKEND does (the variable overrides every scenario's camera.backend), and an "osmesa"
// forced over a file's "egl" is cached.
TEST(WorldCacheEligibility, TheBackEndTheRunDrawsWithDecides) {
  const auto with_env = [](const char* value, const Json& j) {
    const char* old = std::getenv("OMNILOC_GL_BACKEND");
    const std::string kept = old ? old : "";
    if (value) ::setenv("OMNILOC_GL_BACKEND", value, 1);
    else ::unsetenv("OMNILOC_GL_BACKEND");
    std::string why;
    try {
      why = world_cache_ineligible(scenario(j), RunOptions{});
    } catch (...) {
      why = "(egl cannot render here)";
    }
    if (old) ::setenv("OMNILOC_GL_BACKEND", kept.c_str(), 1);
    else ::unsetenv("OMNILOC_GL_BACKEND");
    return why;
  };
  const Json plain = tracking_json(1.0);
  Json egl = plain;
  egl["camera"]["backend"] = "egl";
  EXPECT_EQ(with_env(nullptr, plain), "");
  EXPECT_EQ(with_env("osmesa", egl), "");
  EXPECT_NE(with_env(nullptr, egl), "");
  EXPECT_NE(with_env("egl", plain), "");
}

TEST_F(WorldCacheTest, ADamagedEntryIsRedrawnNeverUsed) {
  const Scenario sc = scenario(tracking_json(1.0));
  WorldCache c = cache();
  std::string dir;
  {
    const WorldLease l = c.get(sc, 1, false);
    EXPECT_TRUE(l.drawn());
    dir = l.dir();
  }
  const std::string frames = slurp(fs::path(dir) / "frames.jsonl.gz");
  {
    const WorldLease l = c.get(sc, 1, false);
    EXPECT_FALSE(l.drawn());
  }
  // One byte changed, the file cut, a file gone, the manifest gone: each is found and redrawn.
  const auto damage = std::vector<std::function<void()>>{
      [&] {
        std::string f = frames;
        f[f.size() / 2] ^= 0x01;
        std::ofstream(fs::path(dir) / "frames.jsonl.gz", std::ios::binary) << f;
      },
      [&] { std::ofstream(fs::path(dir) / "frames.jsonl.gz", std::ios::binary) << frames.substr(0, frames.size() / 3); },
      [&] { fs::remove(fs::path(dir) / "recording.json"); },
      [&] { fs::remove(fs::path(dir) / "entry.json"); }};
  for (std::size_t i = 0; i < damage.size(); ++i) {
    damage[i]();
    EXPECT_FALSE(c.find(world_key(sc, 1, false)).has_value()) << i;
    const WorldLease l = c.get(sc, 1, false);
    EXPECT_TRUE(l.drawn()) << i;
    EXPECT_EQ(slurp(fs::path(dir) / "frames.jsonl.gz"), frames) << i;  // drawn again: the same bytes
  }
}

TEST_F(WorldCacheTest, PruneRemovesTheLeastRecentlyUsedButNeverOneInUse) {
  const Scenario sc = scenario(tracking_json(0.5));
  WorldCache c = cache();
  std::vector<std::string> dirs;
  for (std::uint64_t seed : {1, 2, 3}) dirs.push_back(c.get(sc, seed, false).dir());
  // Last used: seed 1 three days ago, seed 2 two days ago, seed 3 now.
  const std::time_t now = std::time(nullptr);
  for (int i = 0; i < 2; ++i) {
    const struct timespec t[2] = {{now - (3 - i) * 86400, 0}, {now - (3 - i) * 86400, 0}};
    ASSERT_EQ(::utimensat(AT_FDCWD, (fs::path(dirs[i]) / "last_used").c_str(), t, 0), 0);
  }
  const auto list = c.list();
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list.front().seed, 3u);  // newest first
  const std::uint64_t one = list.front().bytes;
  // Older than 2.5 days: seed 1 only.
  PruneResult r = c.prune(2.5 * 86400, std::nullopt);
  EXPECT_EQ(r.removed, 1u);
  EXPECT_FALSE(fs::exists(dirs[0]));
  // Room for one entry, while seed 2, now the least recently used, is in use: it is kept, seed 3 goes.
  {
    auto held = c.find(world_key(sc, 2, false));
    ASSERT_TRUE(held.has_value());
    const struct timespec t[2] = {{now - 86400, 0}, {now - 86400, 0}};
    ASSERT_EQ(::utimensat(AT_FDCWD, (fs::path(dirs[1]) / "last_used").c_str(), t, 0), 0);
    r = c.prune(std::nullopt, one + one / 2);
    EXPECT_EQ(r.busy, 1u);
    EXPECT_EQ(r.removed, 1u);
    EXPECT_TRUE(fs::exists(dirs[1]));
    EXPECT_FALSE(fs::exists(dirs[2]));
  }
  r = c.prune(std::nullopt, 0);
  EXPECT_EQ(c.list().size(), 0u);
  // A size limit in the options evicts after each new drawing.
  WorldCache small = cache(one + one / 2);
  for (std::uint64_t seed : {4, 5, 6}) (void)small.get(sc, seed, false);
  EXPECT_EQ(small.list().size(), 1u);
  EXPECT_EQ(small.list().front().seed, 6u);
}
