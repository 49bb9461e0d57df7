#include "harness/recording/frames_reader.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string_view>

#include <simdjson.h>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "external/sha256.hpp"
#include "harness/recording/format/gzip.hpp"
#include "harness/recording/format/frame_codec.hpp"
#include "harness/recording/format/limits.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {

// The fast path accepts only values the strict reader accepts: the same limits.
using namespace recording_limits;
// Decompressed bytes read at a time; a line longer than the buffer grows it.
constexpr std::size_t kChunk = 1 << 18;

// The fast path: true when `el` was read into `out` exactly as frame_from_json reads it. Any doubt
// is false, and the line goes to the strict reader.
using simdjson::dom::element;
using simdjson::dom::element_type;

bool number(element el, double& out) {
  switch (el.type()) {
    case element_type::INT64: out = static_cast<double>(int64_t(el)); return true;
    case element_type::UINT64: out = static_cast<double>(uint64_t(el)); return true;
    case element_type::DOUBLE: out = double(el); return std::isfinite(out);
    default: return false;
  }
}
bool in_range(element el, double lo, double hi, double& out) { return number(el, out) && out >= lo && out <= hi; }
bool length(element el, double& out) { return in_range(el, -kMaxLength, kMaxLength, out); }
bool angle(element el, double& out) { return in_range(el, -kMaxAngle, kMaxAngle, out); }
bool boolean(element el, bool& out) {
  if (el.type() != element_type::BOOL) return false;
  out = bool(el);
  return true;
}

bool pose(element el, Pose2& out) {
  simdjson::dom::array a;
  if (el.get_array().get(a) || a.size() != 3) return false;
  double v[3];
  std::size_t i = 0;
  for (element x : a) {
    if (!(i < 2 ? length(x, v[i]) : angle(x, v[i]))) return false;
    ++i;
  }
  out = Pose2(v[0], v[1], v[2]);
  return true;
}

// Each known key once: bit i of `seen` is key i.
bool first_time(unsigned& seen, int bit) {
  if (seen & (1u << bit)) return false;
  seen |= 1u << bit;
  return true;
}

bool robot_fast(element el, double t, const RecordedRobot& expected, bool truth, RobotFrame& r) {
  simdjson::dom::object o;
  if (el.get_object().get(o)) return false;
  enum { kRobot, kOdometry, kHeading, kCameraOk, kLinePoints, kCovered, kCamera, kStop, kContact, kTruth };
  unsigned seen = 0;
  r.id = expected.id;
  r.odometry.t = t;
  r.obs.t = t;
  for (auto field : o) {
    const std::string_view key = field.key;
    element v = field.value;
    if (key == "robot") {
      if (!first_time(seen, kRobot) || v.type() != element_type::INT64 || int64_t(v) != expected.id) return false;
    } else if (key == "odometry") {
      if (!first_time(seen, kOdometry) || !pose(v, r.odometry.delta)) return false;
    } else if (key == "heading") {
      if (!first_time(seen, kHeading)) return false;
      if (!v.is_null()) {
        double h = 0;
        if (!angle(v, h)) return false;
        r.heading = h;
      }
    } else if (key == "camera_ok") {
      if (!first_time(seen, kCameraOk) || !boolean(v, r.obs.camera_ok)) return false;
    } else if (key == "line_points") {
      simdjson::dom::array pts;
      if (!first_time(seen, kLinePoints) || v.get_array().get(pts)) return false;
      r.obs.line_points.reserve(pts.size());
      for (element p : pts) {
        simdjson::dom::array xy;
        if (p.get_array().get(xy) || xy.size() != 2) return false;
        double x = 0, y = 0;
        if (!length(xy.at(0).value_unsafe(), x) || !length(xy.at(1).value_unsafe(), y)) return false;
        r.obs.line_points.emplace_back(x, y);
      }
    } else if (key == "covered") {
      if (!first_time(seen, kCovered) || !boolean(v, r.covered)) return false;
    } else if (key == "camera") {
      if (!first_time(seen, kCamera)) return false;
      if (!v.is_null()) {
        simdjson::dom::object c;
        if (v.get_object().get(c)) return false;
        unsigned cs = 0;
        CameraSettings s{};
        for (auto cf : c) {
          if (cf.key == "exposure_ms") {
            if (!first_time(cs, 0) || !in_range(cf.value, 0.0, kMaxExposureMs, s.exposure_ms)) return false;
          } else if (cf.key == "gain") {
            if (!first_time(cs, 1) || !in_range(cf.value, 0.0, kMaxGain, s.gain)) return false;
          } else {
            return false;
          }
        }
        if (cs != 3u) return false;
        r.settings = s;
      }
    } else if (key == "stop_robot") {
      if (!first_time(seen, kStop) || !boolean(v, r.stop_robot)) return false;
    } else if (key == "contact") {
      if (!first_time(seen, kContact) || !boolean(v, r.contact)) return false;
    } else if (key == "truth" && truth) {
      Pose2 p;
      if (!first_time(seen, kTruth) || !pose(v, p)) return false;
      r.truth = p;
    } else {
      return false;  // blobs, events, a key of a later version, a truth the header says is absent
    }
  }
  constexpr unsigned required = (1u << kRobot) | (1u << kOdometry) | (1u << kHeading) | (1u << kCameraOk) | (1u << kLinePoints);
  if ((seen & required) != required) return false;
  return !truth || (seen & (1u << kTruth));
}

bool frame_fast(element doc, const std::vector<RecordedRobot>& robots, bool truth, FrameData& f) {
  simdjson::dom::object o;
  if (doc.get_object().get(o)) return false;
  unsigned seen = 0;
  simdjson::dom::array rs;
  for (auto field : o) {
    if (field.key == "k") {
      if (!first_time(seen, 0) || field.value.type() != element_type::INT64 || int64_t(field.value) < 0) return false;
      f.k = int64_t(field.value);
    } else if (field.key == "t") {
      if (!first_time(seen, 1) || !in_range(field.value, 0.0, kMaxTime, f.t)) return false;
    } else if (field.key == "robots") {
      if (!first_time(seen, 2) || field.value.get_array().get(rs)) return false;
    } else {
      return false;  // events, or a key of a later version
    }
  }
  if (seen != 7u || rs.size() != robots.size()) return false;
  f.robots.resize(robots.size());
  std::size_t i = 0;
  for (element r : rs) {
    if (!robot_fast(r, f.t, robots[i], truth, f.robots[i])) return false;
    ++i;
  }
  return true;
}

// Where the decompressed bytes come from: the gzip stream or the plain file.
class Bytes {
 public:
  virtual ~Bytes() = default;
  virtual std::size_t read(char* out, std::size_t n) = 0;  // 0 at the end; throws std::runtime_error
};
class GzipBytes : public Bytes {
 public:
  explicit GzipBytes(const std::string& path) : gz_(path) {}
  std::size_t read(char* out, std::size_t n) override { return gz_.read(out, n); }

 private:
  GzipFileReader gz_;
};
class PlainBytes : public Bytes {
 public:
  explicit PlainBytes(const std::string& path) : f_(std::fopen(path.c_str(), "rb")) {
    if (!f_) throw std::runtime_error(std::string("cannot open: ") + std::strerror(errno));
  }
  ~PlainBytes() override { std::fclose(f_); }
  std::size_t read(char* out, std::size_t n) override {
    const std::size_t got = std::fread(out, 1, n, f_);
    if (got == 0 && std::ferror(f_)) throw std::runtime_error(std::string("read error: ") + std::strerror(errno));
    return got;
  }

 private:
  std::FILE* f_;
};

}  // namespace

struct FramesReader::State {
  std::string file;
  long long frames = 0;
  std::string sha256;
  std::vector<RecordedRobot> robots;
  bool truth = true;
  bool gz = false;
  std::unique_ptr<Bytes> bytes;
  external::Sha256 hash;
  std::uintmax_t total = 0;  // decompressed bytes so far
  // buf[pos, len) is what is read and not yet returned; simdjson reads up to SIMDJSON_PADDING bytes
  // past a line's end, so the buffer always has that much beyond `len`.
  std::vector<char> buf = std::vector<char>(kChunk + simdjson::SIMDJSON_PADDING);
  std::size_t pos = 0, len = 0;
  bool at_end = false, done = false;
  long long line_no = 0;
  double prev_t = 0.0;
  simdjson::dom::parser parser;
  long long fast = 0, strict = 0;

  // More bytes into the buffer (keeping buf[pos, len)); false at the end of the data.
  bool refill() {
    if (at_end) return false;
    if (pos > 0) {
      std::memmove(buf.data(), buf.data() + pos, len - pos);
      len -= pos;
      pos = 0;
    }
    if (buf.size() - simdjson::SIMDJSON_PADDING - len < kChunk / 2) buf.resize(buf.size() * 2);
    std::size_t got = 0;
    try {
      got = bytes->read(buf.data() + len, buf.size() - simdjson::SIMDJSON_PADDING - len);
    } catch (const std::exception& e) {
      throw ConfigError(file, e.what(), gz ? "a whole gzip stream of frames.jsonl" : "a readable file");
    }
    if (got == 0) {
      at_end = true;
      return false;
    }
    if (total + got > kMaxFramesBytes)
      throw ConfigError(file, "more than " + std::to_string(kMaxFramesBytes) + " bytes uncompressed", "a whole gzip stream of frames.jsonl");
    total += got;
    hash.add(buf.data() + len, got);
    len += got;
    return true;
  }

  // The SHA-256 recording.json gives (none in some other writers' recordings), checked once every
  // byte has been read.
  bool hashed = false;
  void check_hash() {
    if (sha256.empty() || hashed) return;
    hashed = true;
    const std::string h = hash.hex();
    if (h != sha256)
      throw ConfigError(file, "SHA-256 " + h, "the SHA-256 recording.json gives (" + sha256 + "): the file was changed or cut short");
  }

  // An error found in a line: the whole-file reader checked the stream and the hash before any line,
  // so those are read to the end first and, when wrong, reported instead.
  [[noreturn]] void line_error(const ConfigError& e) {
    done = true;
    pos = len = 0;
    while (refill()) pos = len;
    check_hash();
    throw e;
  }
};

FramesReader::FramesReader(const RecordingHeader& h) : s_(std::make_unique<State>()) {
  State& s = *s_;
  s.file = (fs::path(h.dir) / h.frames_file).string();
  s.frames = h.frames;
  s.sha256 = h.frames_sha256;
  s.robots = h.robots;
  s.truth = h.ground_truth;
  s.gz = h.frames_file.size() > 3 && h.frames_file.compare(h.frames_file.size() - 3, 3, ".gz") == 0;
  if (const std::string why = why_not_readable_file(s.file); !why.empty())
    throw ConfigError(s.file, why, "a readable file of the recording (docs/recording.md)");
  std::error_code ec;
  const auto size = fs::file_size(s.file, ec);
  if (ec) throw ConfigError(s.file, ec.message(), "a readable file of the recording (docs/recording.md)");
  if (size > kMaxFramesBytes) throw ConfigError(s.file, std::to_string(size) + " bytes", "at most " + std::to_string(kMaxFramesBytes) + " bytes");
  try {
    if (s.gz) s.bytes = std::make_unique<GzipBytes>(s.file);
    else s.bytes = std::make_unique<PlainBytes>(s.file);
  } catch (const std::exception& e) {
    throw ConfigError(s.file, e.what(), "a readable file");
  }
}

FramesReader::~FramesReader() = default;

long long FramesReader::fast_lines() const { return s_->fast; }
long long FramesReader::strict_lines() const { return s_->strict; }

std::optional<FrameData> FramesReader::next() {
  State& s = *s_;
  if (s.done) return std::nullopt;
  // The next whole line.
  std::size_t nl = std::string_view::npos;
  for (std::size_t from = s.pos;;) {
    const void* p = std::memchr(s.buf.data() + from, '\n', s.len - from);
    if (p) {
      nl = static_cast<std::size_t>(static_cast<const char*>(p) - s.buf.data());
      break;
    }
    const std::size_t scanned = s.len - s.pos;
    if (!s.refill()) break;
    from = s.pos + scanned;
  }
  if (nl == std::string_view::npos) {
    if (s.len > s.pos)
      s.line_error(ConfigError(s.file + " line " + std::to_string(s.line_no + 1), "a line without its newline", "whole lines (the file is cut short)"));
    s.done = true;
    s.check_hash();
    if (s.line_no != s.frames)
      throw ConfigError(s.file, std::to_string(s.line_no) + " frames", std::to_string(s.frames) + " frames (recording.json): the file is cut short");
    return std::nullopt;
  }
  const char* line = s.buf.data() + s.pos;
  const std::size_t n = nl - s.pos;
  s.pos = nl + 1;
  ++s.line_no;
  const std::string at = s.file + " line " + std::to_string(s.line_no);
  try {
    if (s.line_no > s.frames) throw ConfigError(at, "another frame", std::to_string(s.frames) + " frames (recording.json)");
    FrameData f;
    element doc;
    if (n <= kJsonMaxBytes && !s.parser.parse(line, n, false).get(doc) && frame_fast(doc, s.robots, s.truth, f)) {
      ++s.fast;
    } else {
      ++s.strict;
      f = frame_from_json(parse_json_strict(std::string_view(line, n), at), at + " ", s.robots, s.truth);  // "frames.jsonl line 6 /robots/0/heading"
    }
    if (f.k != s.line_no - 1) throw ConfigError(at + " /k", std::to_string(f.k), "frame " + std::to_string(s.line_no - 1) + " (frames in order from 0)");
    if (s.line_no > 1 && !(f.t > s.prev_t)) throw ConfigError(at + " /t", std::to_string(f.t), "a time after the previous frame's");
    s.prev_t = f.t;
    return f;
  } catch (const ConfigError& e) {
    s.line_error(e);
  }
}

}  // namespace omniloc::harness
