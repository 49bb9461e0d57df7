// The streaming recording reader (harness/recording/frames_reader.hpp) against the whole-file reader it
// replaced, kept here as the reference: on every shipped recording and on hand-made lines at the
// edges of the fast path (integers for doubles, unknown keys, duplicate keys, blobs, events, values
// at and past the limits, damaged files), both give the same frames or the same error message.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/install_paths.hpp"
#include "core/json_parse.hpp"
#include "external/sha256.hpp"
#include "harness/recording/format/gzip.hpp"
#include "harness/recording/format/frame_codec.hpp"
#include "harness/recording/frames_reader.hpp"
#include "harness/recording/recording_source.hpp"

using namespace omniloc;
using namespace omniloc::harness;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The reader of commit d5d7da1 (whole file: decompress, SHA-256, then every line), the reference.
std::vector<FrameData> whole_file_read(const RecordingHeader& h) {
  const std::string file = (fs::path(h.dir) / h.frames_file).string();
  std::string text = slurp(file);
  if (h.frames_file.size() > 3 && h.frames_file.substr(h.frames_file.size() - 3) == ".gz") {
    try {
      text = gzip_decompress(text, 8ULL << 30);
    } catch (const std::exception& e) {
      throw ConfigError(file, e.what(), "a whole gzip stream of frames.jsonl");
    }
  }
  if (!h.frames_sha256.empty() && external::sha256_hex(text) != h.frames_sha256)
    throw ConfigError(file, "SHA-256 " + external::sha256_hex(text),
                      "the SHA-256 recording.json gives (" + h.frames_sha256 + "): the file was changed or cut short");
  std::vector<FrameData> frames;
  long long line_no = 0;
  for (std::size_t a = 0; a < text.size();) {
    const std::size_t b = text.find('\n', a);
    if (b == std::string::npos) throw ConfigError(file + " line " + std::to_string(line_no + 1), "a line without its newline", "whole lines (the file is cut short)");
    ++line_no;
    const std::string at = file + " line " + std::to_string(line_no);
    if (line_no > h.frames) throw ConfigError(at, "another frame", std::to_string(h.frames) + " frames (recording.json)");
    FrameData f = frame_from_json(parse_json_strict(std::string_view(text).substr(a, b - a), at), at + " ", h.robots, h.ground_truth);
    if (f.k != line_no - 1) throw ConfigError(at + " /k", std::to_string(f.k), "frame " + std::to_string(line_no - 1) + " (frames in order from 0)");
    if (!frames.empty() && !(f.t > frames.back().t)) throw ConfigError(at + " /t", std::to_string(f.t), "a time after the previous frame's");
    frames.push_back(std::move(f));
    a = b + 1;
  }
  if (line_no != h.frames)
    throw ConfigError(file, std::to_string(line_no) + " frames", std::to_string(h.frames) + " frames (recording.json): the file is cut short");
  return frames;
}

// Bit-exact comparison of everything a frame carries (doubles compared as bits through ==, and
// -0.0 against 0.0 by signbit).
bool same(double a, double b) { return a == b && std::signbit(a) == std::signbit(b); }
void expect_same_frame(const FrameData& a, const FrameData& b, const std::string& where) {
  SCOPED_TRACE(where);
  ASSERT_EQ(a.k, b.k);
  EXPECT_TRUE(same(a.t, b.t));
  EXPECT_EQ(a.events, b.events);
  ASSERT_EQ(a.robots.size(), b.robots.size());
  for (std::size_t i = 0; i < a.robots.size(); ++i) {
    const RobotFrame& x = a.robots[i];
    const RobotFrame& y = b.robots[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_TRUE(same(x.odometry.t, y.odometry.t));
    EXPECT_TRUE(same(x.odometry.delta.x, y.odometry.delta.x) && same(x.odometry.delta.y, y.odometry.delta.y) &&
                same(x.odometry.delta.theta, y.odometry.delta.theta));
    EXPECT_EQ(x.heading.has_value(), y.heading.has_value());
    if (x.heading && y.heading) {
      EXPECT_TRUE(same(*x.heading, *y.heading));
    }
    EXPECT_TRUE(same(x.obs.t, y.obs.t));
    EXPECT_EQ(x.obs.camera_ok, y.obs.camera_ok);
    ASSERT_EQ(x.obs.line_points.size(), y.obs.line_points.size());
    for (std::size_t j = 0; j < x.obs.line_points.size(); ++j)
      EXPECT_TRUE(same(x.obs.line_points[j].x(), y.obs.line_points[j].x()) && same(x.obs.line_points[j].y(), y.obs.line_points[j].y()));
    ASSERT_EQ(x.obs.blobs.size(), y.obs.blobs.size());
    for (std::size_t j = 0; j < x.obs.blobs.size(); ++j) {
      EXPECT_EQ(x.obs.blobs[j].colour, y.obs.blobs[j].colour);
      EXPECT_TRUE(same(x.obs.blobs[j].bearing, y.obs.blobs[j].bearing));
      EXPECT_TRUE(same(x.obs.blobs[j].distance, y.obs.blobs[j].distance));
      EXPECT_EQ(x.obs.blobs[j].area_px, y.obs.blobs[j].area_px);
    }
    EXPECT_EQ(x.covered, y.covered);
    EXPECT_EQ(x.settings.has_value(), y.settings.has_value());
    if (x.settings && y.settings) {
      EXPECT_TRUE(same(x.settings->exposure_ms, y.settings->exposure_ms) && same(x.settings->gain, y.settings->gain));
    }
    EXPECT_EQ(x.stop_robot, y.stop_robot);
    EXPECT_EQ(x.events, y.events);
    EXPECT_EQ(x.contact, y.contact);
    EXPECT_EQ(x.truth.has_value(), y.truth.has_value());
    if (x.truth && y.truth) {
      EXPECT_TRUE(same(x.truth->x, y.truth->x) && same(x.truth->y, y.truth->y) && same(x.truth->theta, y.truth->theta));
    }
  }
}

struct Outcome {
  std::vector<FrameData> frames;
  std::string error;  // empty: read whole
  long long fast = 0, strict = 0;
};

Outcome streamed(const std::string& dir) {
  Outcome o;
  try {
    RecordingSource s(RecordingHeader::read(dir));
    try {
      while (auto f = s.next()) o.frames.push_back(std::move(*f));
    } catch (const ConfigError& e) {
      o.error = e.what();
    }
    o.fast = s.fast_lines();
    o.strict = s.strict_lines();
  } catch (const ConfigError& e) {
    o.error = e.what();
  }
  return o;
}

Outcome reference(const std::string& dir) {
  Outcome o;
  try {
    o.frames = whole_file_read(RecordingHeader::read(dir));
  } catch (const ConfigError& e) {
    o.error = e.what();
  }
  return o;
}

// The streamed reader equals the reference: the same frames, or the same message (frames a streamed
// read handed out before its error are not compared: a run that meets the error writes nothing).
void expect_equivalent(const std::string& dir) {
  const Outcome s = streamed(dir);
  const Outcome r = reference(dir);
  EXPECT_EQ(s.error, r.error) << dir;
  if (!r.error.empty()) return;
  ASSERT_EQ(s.frames.size(), r.frames.size()) << dir;
  for (std::size_t i = 0; i < s.frames.size(); ++i) expect_same_frame(s.frames[i], r.frames[i], dir + " frame " + std::to_string(i));
}

std::vector<std::string> shipped_recordings() {
  std::vector<std::string> dirs;
  const fs::path root = source_dir();
  for (const auto& sub : {"data/recordings", "data/real", "tests/data"})
    for (const auto& e : fs::recursive_directory_iterator(root / sub))
      if (e.is_regular_file() && e.path().filename() == "recording.json") dirs.push_back(e.path().parent_path().string());
  std::sort(dirs.begin(), dirs.end());
  return dirs;
}

// A copy of the shipped tracking recording (2 s) whose frames are `lines`, written uncompressed or
// gzipped, with a SHA-256 that follows them unless `hash` says otherwise.
class Edited : public ::testing::Test {
 protected:
  void SetUp() override {
    src_ = source_dir() / "data/recordings/ci_tracking/1";
    dir_ = fs::temp_directory_path() / ("omniloc_frames_reader_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    lines_.clear();
    const RecordingHeader h = RecordingHeader::read(src_.string());
    const std::string text = gzip_decompress(slurp(src_ / h.frames_file), 1 << 30);
    std::istringstream in(text);
    for (std::string line; std::getline(in, line) && lines_.size() < 20;) lines_.push_back(line);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // Writes the recording; `sha`: "follow" (the lines' hash), "keep" (the original's), "" (none).
  std::string write(bool gz = true, const std::string& sha = "follow", const std::string& tail = "") {
    std::string text;
    for (const auto& l : lines_) text += l + "\n";
    text += tail;
    Json head = read_json_strict((src_ / "recording.json").string(), "recording.json");
    head["frames"] = static_cast<long long>(lines_.size());
    head["frames_file"] = gz ? "frames.jsonl.gz" : "frames.jsonl";
    if (sha == "follow") head["frames_sha256"] = external::sha256_hex(text);
    else if (sha.empty()) head.erase("frames_sha256");
    std::ofstream(dir_ / "recording.json") << head.dump(1);
    fs::remove(dir_ / "frames.jsonl");
    fs::remove(dir_ / "frames.jsonl.gz");
    std::ofstream(dir_ / (gz ? "frames.jsonl.gz" : "frames.jsonl"), std::ios::binary) << (gz ? gzip_compress(text) : text);
    return dir_.string();
  }
  // Replaces the first occurrence of `from` in line `i` by `to`.
  void edit(std::size_t i, const std::string& from, const std::string& to) {
    const auto p = lines_[i].find(from);
    ASSERT_NE(p, std::string::npos) << from << " not in line " << i;
    lines_[i].replace(p, from.size(), to);
  }
  fs::path src_, dir_;
  std::vector<std::string> lines_;
};

}  // namespace

TEST(FramesReader, EveryShippedRecordingReadsAsTheWholeFileReaderReadsIt) {
  const auto dirs = shipped_recordings();
  ASSERT_GE(dirs.size(), 10u);
  for (const auto& d : dirs) expect_equivalent(d);
  // The tracking recordings are what the speed target is about: every line on the fast path.
  const Outcome o = streamed((source_dir() / "data/recordings/ci_tracking/1").string());
  EXPECT_GT(o.fast, 0);
  EXPECT_EQ(o.strict, 0);
}

TEST_F(Edited, ValuesTheFastPathTakesReadAsTheStrictReaderReadsThem) {
  edit(1, "\"k\":1", "\"k\":1 ");                       // whitespace
  edit(2, "\"robots\":[{", "\"robots\":[{\"later_key\":{\"a\":[1,2]},");  // a key of a later version: ignored
  edit(3, "\"k\":3", "\"comment\":\"x\",\"k\":3");      // the same at the frame
  lines_[4] = std::regex_replace(lines_[4], std::regex("\"heading\":[-0-9.e]+"), "\"heading\":0");  // an integer for a double
  const std::string dir = write();
  expect_equivalent(dir);
  const Outcome o = streamed(dir);
  EXPECT_EQ(o.strict, 2);  // the two lines with unknown keys went to the strict reader
}

TEST_F(Edited, EveryRefusalHasTheWholeFileReadersMessage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"\"k\":5", "\"k\":5.0"},          {"\"k\":5", "\"k\":5,\"k\":5"},  {"\"camera_ok\":", "\"camera_ok\":1,\"camera_ok\":"},
      {"\"camera_ok\":true", "\"camera_ok\":1"}, {"\"heading\":", "\"heading\":1e400,\"x\":"}, {"\"k\":5", "\"k\":18446744073709551615"},
      {"\"line_points\":[[", "\"line_points\":[[50.000001,0],["}, {"\"line_points\":[[", "\"line_points\":[[1,2,3],["},
      {"\"odometry\":[", "\"odometry\":[1e20,"},  {"\"robot\":0", "\"robot\":1"}, {"\"t\":", "\"t\":-1,\"u\":"},
      {"\"truth\":", "\"truth\":null,\"x\":"},     {"\"robots\":[", "\"robots\":[{},"}};
  for (const auto& [from, to] : cases) {
    SCOPED_TRACE(to);
    SetUp();
    edit(5, from, to);
    const std::string dir = write();
    const Outcome s = streamed(dir);
    EXPECT_NE(s.error, "");
    EXPECT_EQ(s.error, reference(dir).error);
    EXPECT_NE(s.error.find("line 6"), std::string::npos) << s.error;
  }
}

TEST_F(Edited, DamageIsNamedBeforeTheFirstBadLineItShows) {
  // A changed value with the old checksum: the checksum is named, as the whole-file reader did.
  edit(5, "\"k\":5", "\"k\":7");
  std::string dir = write(true, "keep");
  EXPECT_NE(streamed(dir).error.find("SHA-256"), std::string::npos);
  expect_equivalent(dir);
  // A cut gzip stream.
  SetUp();
  dir = write();
  const std::string gz = slurp(fs::path(dir) / "frames.jsonl.gz");
  std::ofstream(fs::path(dir) / "frames.jsonl.gz", std::ios::binary) << gz.substr(0, gz.size() / 2);
  EXPECT_NE(streamed(dir).error.find("cut short"), std::string::npos);
  expect_equivalent(dir);
  // Bytes after the gzip stream.
  std::ofstream(fs::path(dir) / "frames.jsonl.gz", std::ios::binary) << gz << "x";
  EXPECT_NE(streamed(dir).error.find("after the end"), std::string::npos);
  expect_equivalent(dir);
  // Uncompressed: a last line without its newline, one frame too many, one too few, no checksum.
  SetUp();
  dir = write(false, "follow", "{\"k\":20");
  EXPECT_NE(streamed(dir).error.find("without its newline"), std::string::npos);
  expect_equivalent(dir);
  SetUp();
  dir = write(false, "", lines_[19] + "\n");
  EXPECT_NE(streamed(dir).error.find("another frame"), std::string::npos);
  expect_equivalent(dir);
  SetUp();
  lines_.pop_back();
  dir = write(false);
  Json head = read_json_strict(dir + "/recording.json", "h");
  head["frames"] = 20;
  std::ofstream(dir + "/recording.json") << head.dump();
  EXPECT_NE(streamed(dir).error.find("cut short"), std::string::npos);
  expect_equivalent(dir);
}
