// The bound cache (harness/bound_cache.hpp): a result through it is byte for byte the bound
// computed afresh, cold or warm; a warm lookup really serves the entry; a damaged entry is said,
// removed and computed again; no cache and an unwritable cache change nothing but a warning; and a
// replay's run folder is the same bytes with the cache cold, warm and off.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <vector>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.hpp"
#include "core/install_paths.hpp"
#include "harness/bound_cache.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/cache/world_cache.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/scoring/bound.hpp"

using namespace omniloc;
using namespace omniloc::harness;
namespace fs = std::filesystem;

namespace {

std::string ci_recording() { return (omniloc::source_dir() / "data/recordings/ci_tracking/1").string(); }

// A recorded robot's frames as scoring gets them (the estimate: the truth shifted, so the
// efficiency has something to measure) and the bound's setup from the recording's scenario.
struct Input {
  Scenario sc;
  RobotRecord rec;
  BoundSetup setup;
};
const Input& input() {
  static const std::unique_ptr<Input> in = [] {
    const RecordingHeader head = RecordingHeader::read(ci_recording());
    auto b = std::make_unique<Input>(Input{replay_scenario(head, LocalizerSpec({{"type", "matching"}}, "/localizer")), {}, {}});
    RecordingSource source(RecordingHeader::read(ci_recording()));
    while (auto f = source.next()) {
      FrameRecord r = bound_frame(f->robots.at(0));
      r.est = Pose2(r.truth.x + 0.02, r.truth.y - 0.01, r.truth.theta + 0.005);
      r.valid = true;
      b->rec.frames.push_back(std::move(r));
    }
    b->setup = bound_setup(b->sc, 0, true);
    b->setup.excluded = {{2.0, 3.5}};
    return b;
  }();
  return *in;
}

// Every byte scoring writes from a RobotBound: the three JSON blocks and each frame's four bounds.
std::string bytes_of(const RobotBound& b) {
  std::ostringstream os;
  os.precision(17);
  os << b.bound.dump() << '\n' << b.efficiency.dump() << '\n' << b.efficiency_single.dump() << '\n';
  for (const auto& f : b.frames)
    for (const auto* v : {&f.pos, &f.heading, &f.ppos, &f.pheading}) os << (*v ? std::to_string(**v) + "/" + [&] {
      std::ostringstream x;
      x << std::hexfloat << **v;
      return x.str();
    }() : std::string("-")) << ' ';
  return os.str();
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("omniloc_bound_cache_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

BoundCache cache_in(const fs::path& dir, std::ostream* log = nullptr) {
  BoundCacheOptions o;
  o.dir = (dir / "build").string();
  o.prune_root = dir.string();
  o.log = log;
  return BoundCache(o);
}

}  // namespace

TEST(BoundCache, ColdAndWarmAreTheFreshBoundByteForByte) {
  const Input& in = input();
  ASSERT_GT(in.rec.frames.size(), 100u);
  const std::string fresh = bytes_of(bound_robot(in.rec, in.setup));
  ASSERT_NE(fresh.find("single_frame"), std::string::npos);
  const fs::path dir = fresh_dir("coldwarm");
  const BoundCache cache = cache_in(dir);
  const std::string entry = cache.entry_path(bound_key(in.rec, in.setup));
  EXPECT_FALSE(fs::exists(entry));
  EXPECT_EQ(bytes_of(bound_robot_cached(in.rec, in.setup, cache)), fresh);  // cold: computed, kept
  ASSERT_TRUE(fs::is_regular_file(entry));
  EXPECT_EQ(bytes_of(bound_robot_cached(in.rec, in.setup, cache)), fresh);  // warm: read back
  // The round trip of the entry alone keeps every bit.
  const BoundPart part = bound_part(in.rec, in.setup);
  const auto back = decode_bound_part(encode_bound_part(part), part.frames.size());
  ASSERT_TRUE(back);
  EXPECT_EQ(bytes_of(bound_from_part(in.rec, in.setup, *back)), fresh);
  fs::remove_all(dir);
}

TEST(BoundCache, AWarmLookupServesTheEntry) {
  // An entry that checks but says something else is what a warm lookup returns: the cache is read,
  // not bypassed (and so the byte-identity above is the entry's, not a recomputation's).
  const Input& in = input();
  const fs::path dir = fresh_dir("serves");
  const BoundCache cache = cache_in(dir);
  BoundPart part = bound_part(in.rec, in.setup);
  part.bound["marker"] = "from the cache";
  part.frames.front().pos = 123.0;
  write_file_atomic(cache.entry_path(bound_key(in.rec, in.setup)), encode_bound_part(part));
  const RobotBound got = bound_robot_cached(in.rec, in.setup, cache);
  EXPECT_EQ(got.bound.value("marker", ""), "from the cache");
  ASSERT_TRUE(got.frames.front().pos);
  EXPECT_EQ(*got.frames.front().pos, 123.0);
  fs::remove_all(dir);
}

TEST(BoundCache, ADamagedEntryIsSaidRemovedAndComputedAgain) {
  const Input& in = input();
  const std::string fresh = bytes_of(bound_robot(in.rec, in.setup));
  const fs::path dir = fresh_dir("damaged");
  std::ostringstream log;
  const BoundCache cache = cache_in(dir, &log);
  const std::string entry = cache.entry_path(bound_key(in.rec, in.setup));
  bound_robot_cached(in.rec, in.setup, cache);
  const std::string good = read_file(entry);
  // One byte changed in a frame's bound, the entry cut short, another layout's header.
  std::string flipped = good;
  flipped[flipped.size() / 3] = static_cast<char>(flipped[flipped.size() / 3] ^ 0x10);
  const std::string cut = good.substr(0, good.size() - 7);
  const std::string other = "omniloc-bound 0\n" + good.substr(16);
  for (const std::string& bad : {flipped, cut, other, std::string()}) {
    log.str("");
    write_file_atomic(entry, bad);
    EXPECT_EQ(bytes_of(bound_robot_cached(in.rec, in.setup, cache)), fresh);
    EXPECT_NE(log.str().find("is damaged"), std::string::npos) << log.str();
    EXPECT_EQ(read_file(entry), good);  // drawn again, whole
  }
  // An entry of another number of frames is not used for these.
  EXPECT_FALSE(decode_bound_part(good, in.rec.frames.size() + 1));
  fs::remove_all(dir);
}

TEST(BoundCache, TheKeyHoldsWhatTheBoundReadsAndNotTheEstimates) {
  const Input& in = input();
  const std::string key = bound_key(in.rec, in.setup);
  EXPECT_EQ(key.size(), 64u);
  EXPECT_EQ(bound_key(in.rec, in.setup), key);
  RobotRecord r = in.rec;
  r.frames[5].est.x += 1.0;  // the localizer's answer: efficiency only
  r.frames[5].valid = false;
  EXPECT_EQ(bound_key(r, in.setup), key);
  BoundSetup s = in.setup;
  s.excluded.clear();  // efficiency only
  EXPECT_EQ(bound_key(in.rec, s), key);
  // One float of one line point one step off, the start pose not given, a kidnap, another camera height.
  r = in.rec;
  std::size_t k = 0;
  while (r.frames[k].line_points.empty()) ++k;
  r.frames[k].line_points[0][0] = std::nextafter(r.frames[k].line_points[0][0], 1e9f);
  EXPECT_NE(bound_key(r, in.setup), key);
  s = in.setup;
  s.start_pose_given = false;
  EXPECT_NE(bound_key(in.rec, s), key);
  s = in.setup;
  s.resets = {3.0};
  EXPECT_NE(bound_key(in.rec, s), key);
  s = in.setup;
  s.mount_height += 1e-12;
  EXPECT_NE(bound_key(in.rec, s), key);
  r = in.rec;
  r.frames[7].heading = r.frames[7].heading ? std::optional<double>() : std::optional<double>(0.0);
  EXPECT_NE(bound_key(r, in.setup), key);
}

TEST(BoundCache, NoCacheWritesNothing) {
  const Input& in = input();
  BoundCacheOptions o;  // OMNILOC_CACHE=off gives an empty folder
  const BoundCache cache(o);
  EXPECT_EQ(cache.entry_path("x"), "");
  EXPECT_EQ(bytes_of(bound_robot_cached(in.rec, in.setup, cache)), bytes_of(bound_robot(in.rec, in.setup)));
  ::setenv("OMNILOC_CACHE", "off", 1);
  EXPECT_EQ(bound_cache_from_env().dir, "");
}

TEST(BoundCacheDeathTest, AnUnwritableCacheWarnsOnceAndTheBoundGoesOn) {
  // In a child process: the warning marks the whole process's cache unwritable.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const Input& in = input();
  const fs::path dir = fresh_dir("unwritable");
  fs::create_directories(dir);
  std::ofstream(dir / "build") << "a file where the folder should be\n";
  EXPECT_EXIT(
      {
        const BoundCache cache = cache_in(dir);
        const bool same = bytes_of(bound_robot_cached(in.rec, in.setup, cache)) == bytes_of(bound_robot(in.rec, in.setup)) &&
                          bytes_of(bound_robot_cached(in.rec, in.setup, cache)) == bytes_of(bound_robot(in.rec, in.setup));
        std::exit(same ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "^omniloc: warning: the cache .* cannot be written \\([^\n]*\\); going on without it\n$");
  fs::remove_all(dir);
}

TEST(BoundCache, AReplaysRunFolderIsTheSameColdWarmAndOff) {
  const RecordingHeader head = RecordingHeader::read(ci_recording());
  const Scenario sc = replay_scenario(head, LocalizerSpec({{"type", "matching"}}, "/localizer"));
  const fs::path root = fresh_dir("runs");
  const auto replay = [&](const std::string& cache, const std::string& name) {
    ::setenv("OMNILOC_CACHE", cache.c_str(), 1);
    RunOptions o;
    o.out_dir = (root / name).string();
    o.replay = true;
    RecordingSource source(RecordingHeader::read(ci_recording()));
    run_frames(sc, head.seed, source, o, Json::object());
    return read_file(o.out_dir + "/frames.csv") + "\n--\n" + read_file(o.out_dir + "/summary.json");
  };
  const std::string cache = (root / "cache").string();
  const std::string cold = replay(cache, "cold");
  ASSERT_NE(cold.find("\"bound\""), std::string::npos);
  EXPECT_EQ(bound_cache_from_env().dir.rfind(cache + "/bounds/", 0), 0u);
  std::size_t entries = 0;
  for (const auto& e : fs::recursive_directory_iterator(cache + "/bounds")) entries += e.path().extension() == ".bound";
  EXPECT_EQ(entries, 1u);
  EXPECT_EQ(replay(cache, "warm"), cold);
  EXPECT_EQ(replay("off", "off"), cold);
  fs::remove_all(root);
}

TEST(BoundCache, PruningKeepsTheMostRecentlyUsed) {
  const Input& in = input();
  const fs::path dir = fresh_dir("prune");
  BoundCacheOptions o;
  o.dir = (dir / "build").string();
  o.prune_root = dir.string();
  const std::string one = encode_bound_part(bound_part(in.rec, in.setup));
  o.max_bytes = 2 * one.size() + one.size() / 2;  // room for two entries
  const BoundCache cache(o);
  BoundSetup s = in.setup;
  std::vector<std::string> keys;
  const auto keep = [&](int i) {
    s.mount_height = in.setup.mount_height + 0.01 * i;
    keys.push_back(bound_key(in.rec, s));
    cache.store(keys.back(), bound_part(in.rec, s));
  };
  const auto now = fs::file_time_type::clock::now();
  keep(0);
  keep(1);
  // Times apart however coarse the file system's clock: the first older than the second ...
  fs::last_write_time(cache.entry_path(keys[0]), now - std::chrono::seconds(100));
  fs::last_write_time(cache.entry_path(keys[1]), now - std::chrono::seconds(50));
  // ... until a hit uses it again; the third entry then leaves room for two: the second goes.
  ASSERT_TRUE(cache.find(keys[0], in.rec.frames.size()));
  keep(2);
  EXPECT_TRUE(fs::exists(cache.entry_path(keys[0])));
  EXPECT_FALSE(fs::exists(cache.entry_path(keys[1])));
  EXPECT_TRUE(fs::exists(cache.entry_path(keys[2])));
  fs::remove_all(dir);
}

TEST(BoundCache, AWritersTemporaryLeftByACrashIsRemovedALiveOneIsNot) {
  const Input& in = input();
  const fs::path dir = fresh_dir("stale");
  const BoundCache cache = cache_in(dir);
  const std::string key = bound_key(in.rec, in.setup);
  fs::create_directories(dir / "build");
  fs::create_directories(dir / "older_build");
  // Named as store() names its temporaries: <entry>.tmp.<pid>.<thread>.<n>.
  const fs::path crashed = dir / "older_build" / "0123.bound.tmp.4242.7.0";
  const fs::path live = fs::path(cache.entry_path(key) + ".tmp.4343.7.0");
  std::ofstream(crashed) << "half an entry";
  std::ofstream(live) << "being written";
  fs::last_write_time(crashed, fs::file_time_type::clock::now() - std::chrono::hours(2));
  cache.store(key, bound_part(in.rec, in.setup));
  EXPECT_FALSE(fs::exists(crashed));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(cache.find(key, in.rec.frames.size()));
  fs::remove_all(dir);
}

TEST(BoundCache, AWorldDrawnKeepsTheBoundsItsReplaysRead) {
  // Drawing a world into the world cache computes its robots' bounds (start pose given and not);
  // its first replay reads one of them: each entry is marked after the draw, and the replay's
  // summary carries the mark.
  const fs::path root = fresh_dir("record");
  ::setenv("OMNILOC_CACHE", (root / "cache").c_str(), 1);
  Json j = Json::parse(std::ifstream((omniloc::source_dir() / "scenarios/paper/tracking.json").string()));
  j["duration"] = 2.0;
  const Scenario live = parse_scenario(j, "bound_cache_record");
  WorldCacheOptions wo;
  wo.dir = (root / "cache" / "worlds").string();
  WorldCache worlds(wo);
  const WorldLease lease = worlds.get(live, 5, false);
  ASSERT_TRUE(lease.drawn());
  const auto entries = [&] {
    std::vector<fs::path> out;
    for (const auto& e : fs::recursive_directory_iterator(root / "cache" / "bounds"))
      if (e.path().extension() == ".bound") out.push_back(e.path());
    return out;
  };
  const RecordingHeader head = RecordingHeader::read(lease.dir());
  ASSERT_EQ(entries().size(), 2u);
  for (const auto& e : entries()) {
    auto part = decode_bound_part(read_file(e.string()), static_cast<std::size_t>(head.frames));
    ASSERT_TRUE(part) << e;
    part->bound["marker"] = e.filename().string();
    write_file_atomic(e.string(), encode_bound_part(*part));
  }
  RunOptions o;
  o.out_dir = (root / "replay").string();
  o.replay = true;
  RecordingSource source(RecordingHeader::read(lease.dir()));
  const RunResult r = run_frames(replay_scenario(head, LocalizerSpec({{"type", "matching"}}, "/localizer")), head.seed, source, o, Json::object());
  EXPECT_TRUE(r.summary["robots"][0]["bound"].contains("marker")) << r.summary["robots"][0]["bound"].dump();
  EXPECT_EQ(entries().size(), 2u);
  fs::remove_all(root);
}
