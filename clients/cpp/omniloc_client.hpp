// omniloc_client.hpp: write an external localizer for omniloc in C++ (protocol olp/1).
//
// One header, C++17, nlohmann-json only. The contract is docs/protocol.md; this header speaks it:
// derive from omniloc_client::Localizer, implement reset() and update(), and return serve(loc)
// from main():
//
//   #include "omniloc_client.hpp"
//   namespace olp = omniloc_client;
//   struct DeadReckoning : olp::Localizer {
//     olp::Pose pose;
//     DeadReckoning() { name = "my_dead_reckoning"; version = "1.0"; needs_start_pose = true; }
//     void reset(std::uint64_t, const std::optional<olp::Pose>& start) override { pose = *start; }
//     olp::Estimate update(const olp::Frame& f) override {
//       pose = olp::compose_odometry(pose, f.odometry);
//       return olp::Estimate{pose};
//     }
//   };
//   int main() { DeadReckoning loc; return olp::serve(loc); }
//
// Units and frames (docs/protocol.md section 4): metres, radians, seconds, angles anticlockwise.
// World frame: origin at the centre spot, x towards the goal at x > 0, y left. Robot frame: origin
// at the robot centre on the floor, x forward, y left. Image: u right (column), v down (row),
// pixel centres at integer + 0.5.
//
// stdout belongs to the protocol: on POSIX, serve() moves the protocol to a private copy of file
// descriptor 1 and points descriptor 1 (std::cout, printf) at stderr, so stray output cannot break it.
#pragma once

#include <array>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#if defined(__unix__) || defined(__APPLE__)
#include <unistd.h>
#define OMNILOC_CLIENT_POSIX 1
#endif

namespace omniloc_client {

inline constexpr const char* kProtocol = "olp/1";
inline constexpr std::size_t kMaxLineBytes = 16u * 1024u * 1024u;
/// frames.csv's own columns: omniloc refuses them as Estimate::extra names.
inline constexpr const char* kReservedExtra[] = {"t",        "robot",     "gt_x",  "gt_y",        "gt_theta", "est_x",     "est_y",
                                                 "est_theta", "err_x",     "err_y", "err_theta",   "err_pos",  "valid",     "mode",
                                                 "camera_ok", "line_points", "match_error", "contact", "exposure_ms", "gain"};
using Json = nlohmann::json;

/// Something this client cannot follow, or an estimate that would break the protocol.
struct ProtocolError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A pose: x, y (metres), theta (radians).
struct Pose {
  double x = 0.0, y = 0.0, theta = 0.0;
};

/// Wraps an angle to (-pi, pi], with the same floating-point steps as omniloc's wrap_angle.
inline double wrap_angle(double a) {
  const double pi = 3.141592653589793238462643383279502884, two_pi = 2.0 * pi;
  a = std::fmod(a + pi, two_pi);
  if (a <= 0.0) a += two_pi;
  return a - pi;
}

/// Dead reckoning: `pose` moved by odometry (dx, dy, dtheta) expressed in the robot frame of
/// `pose`: x += dx cos th - dy sin th; y += dx sin th + dy cos th; th += dtheta, wrapped.
/// The same operations in the same order as omniloc's Pose2::compose (bit-identical results).
inline Pose compose_odometry(const Pose& p, const std::array<double, 3>& odo) {
  const double c = std::cos(p.theta), s = std::sin(p.theta);
  return {p.x + c * odo[0] - s * odo[1], p.y + s * odo[0] + c * odo[1], wrap_angle(p.theta + odo[2])};
}

/// hello.field: the markings (the run folder's field.json). Metres, world frame.
struct Field {
  std::string name;
  double length = 0, width = 0, margin = 0, line_width = 0;
  std::vector<std::array<double, 4>> segments;  ///< line centres x1, y1, x2, y2
  std::vector<std::array<double, 5>> arcs;      ///< cx, cy, radius, start, sweep (anticlockwise)
  std::vector<std::array<double, 3>> spots;     ///< cx, cy, radius
  std::vector<std::array<double, 3>> goals;     ///< goal_line_x, width, depth
  std::vector<std::string> goal_colours;
  Json raw;  ///< the object as sent (landmarks and any later fields)

  /// Exact distance (metres) from the world point (x, y) to the nearest marking: a line's or an
  /// arc's centre line, or a spot's rim (0 inside a spot). The same distance as omniloc's own
  /// distance map (core/field.hpp Field::distance_to_marking; tests/field_distance_test.cpp).
  double distance_to_lines(double x, double y) const {
    double best = HUGE_VAL;
    for (const auto& s : segments) {
      const double ex = s[2] - s[0], ey = s[3] - s[1], ll = ex * ex + ey * ey;
      double t = ll == 0.0 ? 0.0 : ((x - s[0]) * ex + (y - s[1]) * ey) / ll;
      t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
      best = std::min(best, std::hypot(x - (s[0] + t * ex), y - (s[1] + t * ey)));
    }
    const double two_pi = 2.0 * 3.141592653589793238462643383279502884;
    for (const auto& a : arcs) {
      const double ang = std::atan2(y - a[1], x - a[0]);
      double rel = std::fmod(a[4] >= 0 ? ang - a[3] : a[3] - ang, two_pi);
      if (rel < 0) rel += two_pi;
      if (rel <= std::abs(a[4])) {
        best = std::min(best, std::abs(std::hypot(x - a[0], y - a[1]) - a[2]));
      } else {
        for (double e : {a[3], a[3] + a[4]})
          best = std::min(best, std::hypot(x - (a[0] + a[2] * std::cos(e)), y - (a[1] + a[2] * std::sin(e))));
      }
    }
    // Spots (centre and penalty marks) are filled discs: a point inside is on paint.
    for (const auto& s : spots) best = std::min(best, std::max(0.0, std::hypot(x - s[0], y - s[1]) - s[2]));
    return best;
  }
};

/// The pixel -> robot-frame floor map of hello.camera.calibration: linear interpolation along the
/// radius within each calibrated bearing and between the two neighbouring bearings (within a few
/// millimetres of omniloc's 4-point Lagrange map).
class Calibration {
 public:
  Calibration() = default;
  explicit Calibration(const Json& camera) {
    const Json& cal = camera.at("calibration");
    const auto centre = camera.at("mirror_centre_px").get<std::vector<double>>();
    if (centre.size() != 2) throw ProtocolError("hello.camera.mirror_centre_px: expected [cu, cv]");
    cu_ = centre[0];
    cv_ = centre[1];
    radii_ = cal.at("radii_px").get<std::vector<std::vector<double>>>();
    distances_ = cal.at("distances_m").get<std::vector<std::vector<double>>>();
    if (radii_.empty() || radii_.size() != distances_.size())
      throw ProtocolError("hello.camera.calibration: radii_px and distances_m differ");
    for (std::size_t i = 0; i < radii_.size(); ++i)
      if (radii_[i].size() < 2 || radii_[i].size() != distances_[i].size())
        throw ProtocolError("hello.camera.calibration: a bearing's radii_px and distances_m differ");
    min_radius_ = cal.at("min_radius_px").get<double>();
    max_radius_ = cal.at("max_radius_px").get<double>();
  }
  double min_radius() const { return min_radius_; }
  double max_radius() const { return max_radius_; }
  std::array<double, 2> mirror_centre() const { return {cu_, cv_}; }

  /// Radius (pixels from the mirror centre) and robot bearing (radians) of pixel (u, v) (column,
  /// row; its centre at u + 0.5, v + 0.5).
  std::pair<double, double> pixel_polar(double u, double v) const {
    const double du = u + 0.5 - cu_, dv = v + 0.5 - cv_;
    return {std::hypot(du, dv), std::atan2(-du, -dv)};
  }
  /// Floor distance (metres) at image radius r along robot bearing b; nullopt outside the map.
  std::optional<double> distance(double r, double b) const {
    if (radii_.empty() || !(r >= min_radius_ && r <= max_radius_)) return std::nullopt;
    const double two_pi = 2.0 * 3.141592653589793238462643383279502884;
    const std::size_t n = radii_.size();
    double x = std::fmod(b, two_pi);
    if (x < 0) x += two_pi;
    x /= two_pi / static_cast<double>(n);
    const double fl = std::floor(x), w = x - fl;
    const std::size_t i = static_cast<std::size_t>(fl) % n, j = (i + 1) % n;
    const double di = interp(i, r), dj = interp(j, r);
    return di + w * (dj - di);
  }
  /// Robot-frame floor point (x forward, y left; metres) at pixel (u, v); nullopt outside the map.
  std::optional<std::array<double, 2>> to_robot(double u, double v) const {
    const auto [r, b] = pixel_polar(u, v);
    const auto d = distance(r, b);
    if (!d) return std::nullopt;
    return std::array<double, 2>{*d * std::cos(b), *d * std::sin(b)};
  }

 private:
  double interp(std::size_t k, double r) const {
    const auto& rs = radii_[k];
    const auto& ds = distances_[k];
    std::size_t lo = 0, hi = rs.size() - 1;
    if (r <= rs.front()) {
      hi = 1;
    } else if (r >= rs.back()) {
      lo = hi - 1;
    } else {
      while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        (rs[mid] <= r ? lo : hi) = mid;
      }
    }
    const double w = (r - rs[lo]) / (rs[hi] - rs[lo]);
    return ds[lo] + w * (ds[hi] - ds[lo]);
  }
  double cu_ = 0, cv_ = 0, min_radius_ = 0, max_radius_ = 0;
  std::vector<std::vector<double>> radii_, distances_;
};

/// The `hello` message.
struct Hello {
  std::string protocol, omniloc, scenario;
  int robot = 0;
  double camera_rate_hz = 30, duration_s = 0;  ///< frame k at t = k / rate; last k = floor(duration x rate)
  double hello_timeout_s = 60, frame_timeout_s = 10, exit_timeout_s = 5;
  Json params = Json::object();  ///< the scenario's localizer params, unchanged
  Field field;
  Json camera = Json::object();  ///< width, height, channels, layout, mirror_centre_px, calibration, latency_s, mount_height_m, vibration_rad
  Json vision = Json::object();  ///< {"line_points": true, "blobs": bool}
  Json raw;                      ///< the message as sent

  /// hello.camera's pixel -> floor map (throws ProtocolError when hello had none).
  Calibration calibration() const {
    if (!camera.contains("calibration")) throw ProtocolError("hello.camera has no calibration");
    return Calibration(camera);
  }
};

/// A coloured region (or a goal edge) from omniloc's blob detection. Robot-frame bearings, radians.
struct Blob {
  std::string colour, kind;
  double bearing = 0, left_bearing = 0, right_bearing = 0;
  std::optional<double> distance;  ///< metres, when known
  int area_px = 0;
  bool left_occluded = false, right_occluded = false;
};

/// One camera frame: exactly what omniloc's built-in localizers get.
struct Frame {
  long long k = 0;                    ///< frame number from 0
  double t = 0;                       ///< seconds: the first physics step at or after k / camera_rate_hz
  std::array<double, 3> odometry{};   ///< dx, dy, dtheta since the previous frame, in its robot frame
  std::optional<double> heading;      ///< compass, world frame, radians; nullopt without one
  bool camera_ok = true;              ///< false: image unusable, line_points empty
  std::vector<std::array<double, 2>> line_points;  ///< robot frame, metres
  std::vector<Blob> blobs;
  /// The RGB image (row-major HWC) when wants_image; empty otherwise.
  std::vector<std::uint8_t> image;
  int image_width = 0, image_height = 0;
  Json raw;  ///< the message as sent (without the image)
  /// Pixel (u, v)'s channel c (0 R, 1 G, 2 B).
  std::uint8_t at(int u, int v, int c) const {
    return image[(static_cast<std::size_t>(v) * static_cast<std::size_t>(image_width) + static_cast<std::size_t>(u)) * 3 +
                 static_cast<std::size_t>(c)];
  }
};

/// The answer to a frame: pose in the world frame; valid = false while searching; optional
/// covariance (row-major 3x3 over x, y, theta), mode ([a-z0-9_], <= 32), extra (named numbers,
/// frames.csv columns).
struct Estimate {
  Pose pose;
  bool valid = true;
  std::optional<std::array<double, 9>> covariance;
  std::string mode;                    ///< empty: not sent
  std::map<std::string, double> extra; ///< empty: not sent (sorted keys: deterministic bytes); not kReservedExtra
  /// Your own computation time for this frame (ms), written to timing.csv beside the round trip.
  /// run() fills it with the time update() took when you leave it empty.
  std::optional<double> compute_ms;
};

/// Derive from this. Set name/version/needs_start_pose/wants_image in the constructor or ready().
class Localizer {
 public:
  virtual ~Localizer() = default;
  std::string name = "cpp_localizer";  ///< 1-64 of [A-Za-z0-9_.-], not a built-in localizer's name
  std::string version = "0.0";         ///< up to 128 characters
  bool needs_start_pose = false;       ///< true: reset() gets the true start pose
  bool wants_image = false;            ///< true: every frame carries the image
  Hello hello;                         ///< set before ready() is called

  /// After hello, before ready is sent: read params, build maps (counts into hello_timeout_s).
  virtual void ready(const Hello&) {}
  /// Once before frame 0: seed every random generator from `seed`; `start` when needs_start_pose.
  virtual void reset(std::uint64_t seed, const std::optional<Pose>& start) = 0;
  /// Once per frame, in order.
  virtual Estimate update(const Frame& frame) = 0;
  /// On `end`, before the process exits 0.
  virtual void end() {}
};

namespace detail {

inline bool name_ok(const std::string& s, std::size_t max, bool lower_only, bool dot_dash) {
  if (s.empty() || s.size() > max) return false;
  for (char ch : s) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || (!lower_only && ch >= 'A' && ch <= 'Z') ||
                    (dot_dash && (ch == '.' || ch == '-'));
    if (!ok) return false;
  }
  return true;
}

inline double finite(const Json& j, const char* what) {
  if (!j.is_number()) throw ProtocolError(std::string(what) + ": expected a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw ProtocolError(std::string(what) + ": not finite");
  return v;
}

/// The estimate message for frame k (ProtocolError for what omniloc would reject).
inline std::string estimate_line(const Estimate& e, long long k) {
  const auto check = [k](double v, const char* what) {
    if (!std::isfinite(v)) throw ProtocolError("estimate for frame " + std::to_string(k) + ": " + what + " is not finite");
    return v;
  };
  Json m = {{"type", "estimate"},
            {"k", k},
            {"pose", {check(e.pose.x, "pose x"), check(e.pose.y, "pose y"), check(e.pose.theta, "pose theta")}},
            {"valid", e.valid}};
  if (e.covariance) {
    Json c = Json::array();
    for (double v : *e.covariance) c.push_back(check(v, "covariance"));
    m["covariance"] = c;
  }
  if (!e.mode.empty()) {
    if (!name_ok(e.mode, 32, true, false)) throw ProtocolError("estimate: mode '" + e.mode + "' is not [a-z0-9_]{1,32}");
    m["mode"] = e.mode;
  }
  if (!e.extra.empty()) {
    if (e.extra.size() > 32) throw ProtocolError("estimate: more than 32 extra values");
    Json x = Json::object();
    for (const auto& [key, v] : e.extra) {
      if (!name_ok(key, 32, false, false)) throw ProtocolError("estimate: extra name '" + key + "' is not [A-Za-z0-9_]{1,32}");
      for (const char* c : kReservedExtra)
        if (key == c) throw ProtocolError("estimate: extra name '" + key + "' is a column of frames.csv already; choose another name");
      x[key] = check(v, "an extra value");
    }
    m["extra"] = x;
  }
  if (e.compute_ms) {
    if (!(*e.compute_ms >= 0.0) || !std::isfinite(*e.compute_ms)) throw ProtocolError("estimate: compute_ms must be a finite number >= 0");
    m["compute_ms"] = *e.compute_ms;
  }
  return m.dump() + "\n";
}

// One message; false at a clean end-of-file before its first byte.
inline bool read_message(std::istream& in, Json& msg, std::vector<std::uint8_t>& image, std::vector<int>& image_shape) {
  std::string line;
  if (!std::getline(in, line)) {
    if (!line.empty()) throw ProtocolError("end of input inside a message");
    return false;
  }
  if (in.eof()) throw ProtocolError("end of input inside a message");
  if (line.size() > kMaxLineBytes) throw ProtocolError("a line longer than 16 MiB");
  try {
    msg = Json::parse(line);
  } catch (const Json::exception& e) {
    throw ProtocolError(std::string("not a JSON line (") + e.what() + "): " + line.substr(0, 200));
  }
  if (!msg.is_object() || !msg.contains("type") || !msg["type"].is_string())
    throw ProtocolError("not a JSON object with a string 'type': " + line.substr(0, 200));
  image.clear();
  image_shape.clear();
  if (msg.contains("binary")) {
    std::vector<std::uint8_t> buf;
    for (const auto& p : msg["binary"]) {
      if (!p.is_object() || !p.contains("bytes") || !p["bytes"].is_number_unsigned())
        throw ProtocolError("malformed binary part: " + p.dump());
      const auto n = p["bytes"].get<std::uint64_t>();
      buf.resize(static_cast<std::size_t>(n));
      in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n));  // loops over short reads
      if (static_cast<std::uint64_t>(in.gcount()) != n)
        throw ProtocolError("end of input inside a binary part (" + std::to_string(in.gcount()) + " of " + std::to_string(n) + " bytes)");
      if (p.value("name", std::string()) == "image") {
        image.swap(buf);
        if (p.contains("shape")) image_shape = p["shape"].get<std::vector<int>>();
      }
    }
  }
  return true;
}

inline Frame parse_frame(Json& msg, std::vector<std::uint8_t>& image, const std::vector<int>& shape) {
  Frame f;
  try {
    f.k = msg.at("k").get<long long>();
    f.t = finite(msg.value("t", Json(0.0)), "frame.t");
    const Json odo = msg.value("odometry", Json::array({0.0, 0.0, 0.0}));
    if (!odo.is_array() || odo.size() != 3) throw ProtocolError("frame.odometry: expected [dx, dy, dtheta]");
    for (std::size_t i = 0; i < 3; ++i) f.odometry[i] = finite(odo[i], "frame.odometry");
    if (msg.contains("heading") && !msg["heading"].is_null()) f.heading = finite(msg["heading"], "frame.heading");
    f.camera_ok = msg.value("camera_ok", true);
    if (msg.contains("line_points") && msg["line_points"].is_array())
      for (const auto& p : msg["line_points"]) f.line_points.push_back({finite(p.at(0), "line point"), finite(p.at(1), "line point")});
    if (msg.contains("blobs") && msg["blobs"].is_array())
      for (const auto& b : msg["blobs"]) {
        Blob o;
        o.colour = b.value("colour", std::string());
        o.kind = b.value("kind", std::string("region"));
        o.bearing = b.value("bearing", 0.0);
        o.left_bearing = b.value("left_bearing", 0.0);
        o.right_bearing = b.value("right_bearing", 0.0);
        if (b.contains("distance") && b["distance"].is_number()) o.distance = b["distance"].get<double>();
        o.area_px = b.value("area_px", 0);
        o.left_occluded = b.value("left_occluded", false);
        o.right_occluded = b.value("right_occluded", false);
        f.blobs.push_back(std::move(o));
      }
  } catch (const Json::exception& e) {
    throw ProtocolError(std::string("malformed frame: ") + e.what());
  }
  if (!image.empty() || !shape.empty()) {
    if (shape.size() == 3) {
      f.image_height = shape[0];
      f.image_width = shape[1];
    }
    f.image.swap(image);
  }
  f.raw = std::move(msg);
  return f;
}

inline Hello parse_hello(const Json& m) {
  Hello h;
  try {
    h.protocol = m.value("protocol", std::string());
    h.omniloc = m.value("omniloc", std::string());
    h.scenario = m.value("scenario", std::string());
    h.robot = m.value("robot", 0);
    h.camera_rate_hz = m.value("camera_rate_hz", 30.0);
    h.duration_s = m.value("duration_s", 0.0);
    h.hello_timeout_s = m.value("hello_timeout_s", 60.0);
    h.frame_timeout_s = m.value("frame_timeout_s", 10.0);
    h.exit_timeout_s = m.value("exit_timeout_s", 5.0);
    if (m.contains("params") && m["params"].is_object()) h.params = m["params"];
    if (m.contains("camera") && m["camera"].is_object()) h.camera = m["camera"];
    if (m.contains("vision") && m["vision"].is_object()) h.vision = m["vision"];
    if (m.contains("field") && m["field"].is_object()) {
      const Json& f = m["field"];
      h.field.raw = f;
      h.field.name = f.value("name", std::string());
      h.field.length = f.value("length", 0.0);
      h.field.width = f.value("width", 0.0);
      h.field.margin = f.value("margin", 0.0);
      h.field.line_width = f.value("line_width", 0.0);
      if (f.contains("segments")) h.field.segments = f["segments"].get<std::vector<std::array<double, 4>>>();
      if (f.contains("arcs")) h.field.arcs = f["arcs"].get<std::vector<std::array<double, 5>>>();
      if (f.contains("spots")) h.field.spots = f["spots"].get<std::vector<std::array<double, 3>>>();
      if (f.contains("goals")) h.field.goals = f["goals"].get<std::vector<std::array<double, 3>>>();
      if (f.contains("goal_colours")) h.field.goal_colours = f["goal_colours"].get<std::vector<std::string>>();
    }
  } catch (const Json::exception& e) {
    throw ProtocolError(std::string("malformed hello: ") + e.what());
  }
  h.raw = m;
  return h;
}

}  // namespace detail

/// Speaks olp/1 on `in` (from omniloc) until `end` or an error, handing each message line to
/// `send`. Returns the exit status: 0 after `end`; 1 on end-of-file before `end`, a protocol error
/// or an exception from the localizer (explained on `err`). serve() is this on stdin/stdout.
inline int run(Localizer& loc, std::istream& in, const std::function<void(const std::string&)>& send, std::ostream& err) {
  std::string stage = "before hello";
  long long last_k = -1;
  try {
    Json msg;
    std::vector<std::uint8_t> image;
    std::vector<int> shape;
    if (!detail::read_message(in, msg, image, shape)) {
      err << "omniloc_client: end of input before hello" << std::endl;
      return 1;
    }
    if (msg["type"] != "hello") throw ProtocolError("expected hello, got " + msg["type"].get<std::string>());
    if (msg.value("protocol", std::string()) != kProtocol)
      throw ProtocolError("omniloc speaks '" + msg.value("protocol", std::string()) + "', this client speaks olp/1");
    loc.hello = detail::parse_hello(msg);
    stage = "in ready()";
    loc.ready(loc.hello);
    if (!detail::name_ok(loc.name, 64, false, true))
      throw ProtocolError("Localizer::name '" + loc.name + "' must be 1-64 characters of [A-Za-z0-9_.-]");
    if (loc.version.size() > 128) throw ProtocolError("Localizer::version is longer than 128 characters");
    send(Json{{"type", "ready"}, {"protocol", kProtocol}, {"name", loc.name}, {"version", loc.version},
              {"needs_start_pose", loc.needs_start_pose}, {"wants_image", loc.wants_image}}
             .dump() +
         "\n");
    bool was_reset = false;
    while (true) {
      stage = "waiting for a message";
      if (!detail::read_message(in, msg, image, shape)) {
        err << "omniloc_client: end of input before end (last frame " << last_k << "); omniloc has gone" << std::endl;
        return 1;
      }
      const std::string type = msg["type"].get<std::string>();
      if (type == "reset") {
        if (!msg.contains("seed") || !msg["seed"].is_number_integer()) throw ProtocolError("reset: seed must be an integer");
        std::optional<Pose> start;
        if (msg.contains("start") && !msg["start"].is_null()) {
          const Json& s = msg["start"];
          if (!s.is_array() || s.size() != 3) throw ProtocolError("reset: start must be [x, y, theta]");
          start = Pose{detail::finite(s[0], "reset.start"), detail::finite(s[1], "reset.start"), detail::finite(s[2], "reset.start")};
        }
        stage = "in reset()";
        loc.reset(msg["seed"].get<std::uint64_t>(), start);
        was_reset = true;
      } else if (type == "frame") {
        if (!was_reset) throw ProtocolError("frame before reset");
        const Frame f = detail::parse_frame(msg, image, shape);
        last_k = f.k;
        stage = "in update() of frame " + std::to_string(f.k);
        const auto t0 = std::chrono::steady_clock::now();
        Estimate e = loc.update(f);
        if (!e.compute_ms) e.compute_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        send(detail::estimate_line(e, f.k));
      } else if (type == "end") {
        stage = "in end()";
        loc.end();
        return 0;
      } else {
        throw ProtocolError("unexpected message type '" + type + "'");
      }
    }
  } catch (const ProtocolError& e) {
    err << "omniloc_client: protocol error (" << stage << "): " << e.what() << std::endl;
  } catch (const std::exception& e) {
    err << "omniloc_client: the localizer threw (" << stage << "): " << e.what() << std::endl;
  }
  return 1;
}

/// run() on the process's stdin and stdout; returns the exit status for main() to return.
inline int serve(Localizer& loc) {
  std::ios::sync_with_stdio(false);
  std::cin.tie(nullptr);
  std::cout.flush();
#ifdef OMNILOC_CLIENT_POSIX
  // The protocol gets a private copy of descriptor 1; descriptor 1 itself (std::cout, printf) now
  // writes to stderr, so nothing the localizer prints can land in the protocol stream.
  const int proto = ::dup(1);
  if (proto >= 0 && ::dup2(2, 1) >= 0) {
    const auto send = [proto](const std::string& line) {
      const char* p = line.data();
      std::size_t left = line.size();
      while (left > 0) {
        const ssize_t n = ::write(proto, p, left);
        if (n < 0) {
          if (errno == EINTR) continue;
          throw ProtocolError("cannot write to omniloc (the pipe is closed)");
        }
        p += n;
        left -= static_cast<std::size_t>(n);
      }
    };
    const int status = run(loc, std::cin, send, std::cerr);
    ::close(proto);
    return status;
  }
#endif
  const auto send = [](const std::string& line) {
    std::cout.write(line.data(), static_cast<std::streamsize>(line.size()));
    std::cout.flush();
    if (!std::cout) throw ProtocolError("cannot write to omniloc (the pipe is closed)");
  };
  return run(loc, std::cin, send, std::cerr);
}

}  // namespace omniloc_client
