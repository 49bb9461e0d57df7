#include "harness/bound_cache.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <system_error>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/cache_root.hpp"
#include "external/sha256.hpp"
#include "harness/cache/cache_dirs.hpp"
#include "sim/render/camera_config.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

namespace {

// Raised whenever the entry's layout or the key's content changes, so that an older layout is a
// miss, not a damaged entry (the build fingerprint's folder already separates builds).
constexpr char kMagic[] = "omniloc-bound 1\n";
constexpr std::size_t kMagicLen = sizeof(kMagic) - 1;
constexpr std::size_t kHexLen = 64;

template <class T>
void put(std::string& out, const T& v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

// Reads a T at `at`, moving past it; false past the end.
template <class T>
bool get(const std::string& in, std::size_t& at, T& v) {
  if (in.size() - at < sizeof(T)) return false;
  std::memcpy(&v, in.data() + at, sizeof(T));
  at += sizeof(T);
  return true;
}

}  // namespace

BoundCacheOptions bound_cache_from_env() {
  BoundCacheOptions o;
  o.dir = build_cache_dir("bounds");
  o.prune_root = cache::dir("bounds");
  o.log = &std::cerr;
  return o;
}

std::string bound_key(const RobotRecord& robot, const BoundSetup& setup) {
  // Raw bytes, not text: every bit of every number decides (a key that rounded could hit a part
  // computed from other frames). One buffer, hashed once: a run's points are about a megabyte.
  std::string k;
  std::size_t points = 0;
  for (const auto& f : robot.frames) points += f.line_points.size();
  k.reserve(256 + robot.frames.size() * 96 + points * 8);
  k.append(kMagic, kMagicLen);
  put(k, setup.mount_height);
  put(k, setup.latency_s);
  put(k, setup.physics_dt);
  put(k, setup.camera_rate);
  put(k, setup.vibration_std);
  put(k, setup.tilt_per_accel);
  put(k, setup.trans_sigma);
  put(k, setup.rot_sigma);
  put(k, setup.rot_per_trans);
  put(k, setup.scale_sigma);
  put(k, static_cast<std::uint8_t>(setup.has_heading_sensor));
  put(k, setup.heading_sigma);
  put(k, static_cast<std::uint8_t>(setup.start_pose_given));
  put(k, static_cast<std::uint8_t>(setup.has_odometry));
  // In the order given: summary.json's restarts_at_s lists them so.
  put(k, static_cast<std::uint64_t>(setup.resets.size()));
  for (double t : setup.resets) put(k, t);
  const Field& field = *setup.field;
  put(k, field.half_floor_x());
  put(k, field.half_floor_y());
  put(k, static_cast<std::uint64_t>(field.segments.size()));
  for (const auto& s : field.segments) {
    put(k, s.a.x());
    put(k, s.a.y());
    put(k, s.b.x());
    put(k, s.b.y());
  }
  put(k, static_cast<std::uint64_t>(field.arcs.size()));
  for (const auto& a : field.arcs) {
    put(k, a.centre.x());
    put(k, a.centre.y());
    put(k, a.radius);
    put(k, a.start);
    put(k, a.sweep);
  }
  put(k, static_cast<std::uint64_t>(field.spots.size()));
  for (const auto& s : field.spots) {
    put(k, s.centre.x());
    put(k, s.centre.y());
    put(k, s.radius);
  }
  put(k, static_cast<std::uint64_t>(robot.frames.size()));
  for (const auto& f : robot.frames) {
    put(k, f.t);
    put(k, f.truth.x);
    put(k, f.truth.y);
    put(k, f.truth.theta);
    put(k, static_cast<std::uint8_t>(f.camera_ok));
    put(k, f.odometry.x);
    put(k, f.odometry.y);
    put(k, f.odometry.theta);
    put(k, static_cast<std::uint8_t>(f.heading.has_value()));
    put(k, f.heading.value_or(0.0));
    put(k, static_cast<std::uint64_t>(f.line_points.size()));
    if (!f.line_points.empty()) k.append(reinterpret_cast<const char*>(f.line_points.data()), f.line_points.size() * sizeof(f.line_points[0]));
  }
  return external::sha256_hex(k);
}

std::string encode_bound_part(const BoundPart& part) {
  std::string payload;
  payload.reserve(16 + part.frames.size() * 33);
  put(payload, static_cast<std::uint64_t>(part.frames.size()));
  for (const auto& f : part.frames) {
    const std::uint8_t mask = static_cast<std::uint8_t>((f.pos ? 1 : 0) | (f.heading ? 2 : 0) | (f.ppos ? 4 : 0) | (f.pheading ? 8 : 0));
    put(payload, mask);
    for (const auto* v : {&f.pos, &f.heading, &f.ppos, &f.pheading})
      if (*v) put(payload, **v);
  }
  // JSON text keeps every double exactly (shortest round-trip digits) and dumps back to the same bytes.
  payload += part.bound.dump();
  std::string out(kMagic, kMagicLen);
  out += external::sha256_hex(payload);
  out += '\n';
  out += payload;
  return out;
}

std::optional<BoundPart> decode_bound_part(const std::string& bytes, std::size_t frames, std::string* why) {
  const auto fail = [why](const char* w) -> std::optional<BoundPart> {
    if (why) *why = w;
    return std::nullopt;
  };
  if (bytes.size() < kMagicLen + kHexLen + 1 || bytes.compare(0, kMagicLen, kMagic) != 0) return fail("not a bound entry of this layout");
  const std::string payload = bytes.substr(kMagicLen + kHexLen + 1);
  if (bytes[kMagicLen + kHexLen] != '\n' || external::sha256_hex(payload) != bytes.substr(kMagicLen, kHexLen))
    return fail("its content does not match its SHA-256");
  std::size_t at = 0;
  std::uint64_t n = 0;
  if (!get(payload, at, n) || n != frames) return fail("it holds another number of frames");
  BoundPart part;
  part.frames.resize(frames);
  for (auto& f : part.frames) {
    std::uint8_t mask = 0;
    if (!get(payload, at, mask) || mask > 15) return fail("its frames are cut");
    int bit = 0;
    for (auto* v : {&f.pos, &f.heading, &f.ppos, &f.pheading}) {
      if (mask & (1 << bit++)) {
        double x = 0;
        if (!get(payload, at, x)) return fail("its frames are cut");
        *v = x;
      }
    }
  }
  try {
    part.bound = Json::parse(payload.begin() + static_cast<std::ptrdiff_t>(at), payload.end());
  } catch (const Json::exception&) {
    return fail("its summary does not parse");
  }
  if (!part.bound.is_object()) return fail("its summary is not an object");
  return part;
}

std::string BoundCache::entry_path(const std::string& key) const { return o_.dir.empty() ? std::string() : o_.dir + "/" + key + ".bound"; }

std::optional<BoundPart> BoundCache::find(const std::string& key, std::size_t frames) const {
  const std::string path = entry_path(key);
  if (path.empty()) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;  // a miss
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  std::string why;
  std::optional<BoundPart> part = decode_bound_part(bytes, frames, &why);
  std::error_code ec;
  if (!part) {
    if (o_.log) *o_.log << "omniloc: bound cache: entry " << path << " is damaged (" << why << "); removed, computed again\n";
    fs::remove(path, ec);
    return std::nullopt;
  }
  // Least recently used goes first when pruning: a hit is a use (a read-only cache keeps its time).
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);
  return part;
}

void BoundCache::store(const std::string& key, const BoundPart& part) const {
  const std::string path = entry_path(key);
  if (path.empty() || cache::unwritable()) return;
  // Two runs keeping the same entry at once each rename a whole file (the same bytes) over the other's.
  try {
    write_file_atomic(path, encode_bound_part(part));
  } catch (const std::exception& e) {
    cache::report_unwritable(e.what());  // a full or read-only cache costs the computation next time
    return;
  }
  prune();
}

// A writer's temporary (<entry>.tmp.<pid>...) lives for the milliseconds one entry takes to write;
// one an hour old was left by a process that died mid-write and will never be renamed.
constexpr auto kStaleTemporary = std::chrono::hours(1);

void BoundCache::prune() const {
  if (o_.max_bytes == 0) return;
  // Every build's folder under bounds/: an older build's entries are the likeliest to go.
  const fs::path root = o_.prune_root.empty() ? fs::path(o_.dir) : fs::path(o_.prune_root);
  const auto stale_before = fs::file_time_type::clock::now() - kStaleTemporary;
  struct Entry {
    fs::path path;
    fs::file_time_type used;
    std::uint64_t bytes;
  };
  std::vector<Entry> entries;
  std::uint64_t total = 0;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code e2;
    if (!it->is_regular_file(e2)) continue;
    if (it->path().filename().string().find(".bound.tmp.") != std::string::npos) {
      const auto t = it->last_write_time(e2);
      if (!e2 && t < stale_before) fs::remove(it->path(), e2);
      continue;
    }
    if (it->path().extension() != ".bound") continue;
    const std::uint64_t b = it->file_size(e2);
    if (e2) continue;
    const auto t = it->last_write_time(e2);
    if (e2) continue;
    entries.push_back({it->path(), t, b});
    total += b;
  }
  if (total <= o_.max_bytes) return;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used || (a.used == b.used && a.path < b.path); });
  for (const auto& e : entries) {
    if (total <= o_.max_bytes) break;
    std::error_code e3;
    if (fs::remove(e.path, e3)) total -= e.bytes;
  }
}

RobotBound bound_robot_cached(const RobotRecord& robot, const BoundSetup& setup, const BoundCache& cache) {
  if (cache.options().dir.empty()) return bound_robot(robot, setup);
  const std::string key = bound_key(robot, setup);
  if (std::optional<BoundPart> part = cache.find(key, robot.frames.size())) return bound_from_part(robot, setup, std::move(*part));
  BoundPart part = bound_part(robot, setup);
  cache.store(key, part);
  return bound_from_part(robot, setup, std::move(part));
}

BoundSetup bound_setup(const Scenario& sc, int id, bool start_pose_given) {
  BoundSetup b;
  b.field = &sc.field;
  const sim::CameraConfig cam = sim::CameraConfig::from_json(sc.camera, "/camera");
  b.mount_height = cam.mount_height;
  b.latency_s = cam.latency;
  b.vibration_std = cam.vibration_std;
  b.tilt_per_accel = cam.tilt_per_accel;
  b.physics_dt = 1.0 / sc.physics_rate;
  b.camera_rate = sc.camera_rate;
  if (const RobotConfig* rc = sc.robot(id)) {
    b.trans_sigma = rc->odometry.trans_sigma;
    b.rot_sigma = rc->odometry.rot_sigma;
    b.rot_per_trans = rc->odometry.rot_per_trans;
    b.scale_sigma = rc->odometry.scale_sigma;
    b.has_heading_sensor = rc->has_heading_sensor;
    b.heading_sigma = rc->heading.noise_sigma;
  }
  b.start_pose_given = start_pose_given;
  // A move without odometry restarts the posterior bound.
  for (const auto& e : sc.events)
    if (e.robot == id && (e.as<Kidnap>() || e.as<Teleport>())) b.resets.push_back(e.t);
  return b;
}

FrameRecord bound_frame(const RobotFrame& rf) {
  FrameRecord r;
  r.t = rf.obs.t;
  r.truth = rf.truth.value_or(Pose2());
  r.camera_ok = rf.obs.camera_ok;
  r.odometry = rf.odometry.delta;
  r.heading = rf.heading;
  r.line_points.reserve(rf.obs.line_points.size());
  for (const auto& p : rf.obs.line_points) r.line_points.push_back({static_cast<float>(p.x()), static_cast<float>(p.y())});
  return r;
}

}  // namespace omniloc::harness
