#include "external/external_localizer.hpp"

#include <cmath>
#include <functional>
#include <regex>

#include "core/angles.hpp"
#include "core/error.hpp"

namespace omniloc::external {

namespace {

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

std::string fmt_s(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", s);
  return b;
}

const char* kind_name(Blob::Kind k) {
  switch (k) {
    case Blob::Kind::kRegion: return "region";
    case Blob::Kind::kLeftEdge: return "left_edge";
    case Blob::Kind::kRightEdge: return "right_edge";
  }
  return "region";
}

double finite_number(const Json& j, const std::string& at) {
  if (!j.is_number()) throw ProtocolError(at + ": expected a finite number, got " + json_brief(j));
  const double v = j.get<double>();
  if (!std::isfinite(v)) throw ProtocolError(at + ": expected a finite number, got " + json_brief(j));
  return v;
}

// The mode enum of a client's mode word when it is one of ours, so the metrics that count modes
// (coasting, restarts) count the client's too.
LocalizerMode mode_of(const std::string& word) {
  for (int m = static_cast<int>(LocalizerMode::kTracking); m <= static_cast<int>(LocalizerMode::kDeadReckoning); ++m)
    if (word == mode_name(static_cast<LocalizerMode>(m))) return static_cast<LocalizerMode>(m);
  return LocalizerMode::kNone;
}

}  // namespace

ExternalLocalizer::Ready ExternalLocalizer::parse_ready(const Json& msg, const std::vector<std::string>& reserved_names) {
  Ready r;
  const auto name = msg.find("name");
  static const std::regex name_re("[A-Za-z0-9_.-]{1,64}");
  if (name == msg.end() || !name->is_string() || !std::regex_match(name->get<std::string>(), name_re))
    throw ProtocolError("ready: /name: expected 1-64 characters of [A-Za-z0-9_.-], got " + (name == msg.end() ? std::string("nothing") : json_brief(*name)));
  r.name = name->get<std::string>();
  for (const auto& n : reserved_names)
    if (n == r.name || r.name == "external") throw ProtocolError("ready: /name: \"" + r.name + "\" is a built-in localizer's name; choose another");
  const auto version = msg.find("version");
  if (version == msg.end() || !version->is_string() || version->get<std::string>().size() > 128)
    throw ProtocolError("ready: /version: expected a string of at most 128 characters, got " +
                        (version == msg.end() ? std::string("nothing") : json_brief(*version)));
  r.version = version->get<std::string>();
  auto flag = [&](const char* key) {
    const auto it = msg.find(key);
    if (it == msg.end()) return false;
    if (!it->is_boolean()) throw ProtocolError(std::string("ready: /") + key + ": expected true or false, got " + json_brief(*it));
    return it->get<bool>();
  };
  r.needs_start_pose = flag("needs_start_pose");
  r.wants_image = flag("wants_image");
  if (const auto p = msg.find("protocol"); p != msg.end() && *p != kProtocol)
    throw ProtocolError("ready: /protocol: this omniloc speaks " + std::string(kProtocol) + ", the client " + json_brief(*p));
  return r;
}

Estimate ExternalLocalizer::parse_estimate(const Json& msg, long long expected_k) {
  const auto k = msg.find("k");
  if (k == msg.end() || !k->is_number_integer()) throw ProtocolError("estimate: /k: expected the frame number, got " + (k == msg.end() ? std::string("nothing") : json_brief(*k)));
  if (k->get<long long>() != expected_k)
    throw ProtocolError("estimate for frame " + std::to_string(k->get<long long>()) + ", expected " + std::to_string(expected_k));
  Estimate e;
  const auto pose = msg.find("pose");
  if (pose == msg.end() || !pose->is_array() || pose->size() != 3)
    throw ProtocolError("estimate: /pose: expected [x, y, theta], got " + (pose == msg.end() ? std::string("nothing") : json_brief(*pose)));
  e.pose = Pose2(finite_number((*pose)[0], "estimate: /pose/0"), finite_number((*pose)[1], "estimate: /pose/1"),
                 wrap_angle(finite_number((*pose)[2], "estimate: /pose/2")));
  const auto valid = msg.find("valid");
  if (valid == msg.end() || !valid->is_boolean())
    throw ProtocolError("estimate: /valid: expected true or false, got " + (valid == msg.end() ? std::string("nothing") : json_brief(*valid)));
  e.valid = valid->get<bool>();
  if (const auto cov = msg.find("covariance"); cov != msg.end() && !cov->is_null()) {
    if (!cov->is_array() || cov->size() != 9) throw ProtocolError("estimate: /covariance: expected 9 numbers (row-major 3 x 3), got " + json_brief(*cov));
    for (int i = 0; i < 9; ++i) e.covariance(i / 3, i % 3) = finite_number((*cov)[i], "estimate: /covariance/" + std::to_string(i));
  } else {
    e.covariance.setConstant(std::nan(""));  // unknown: frames.csv and metrics do not use it
  }
  if (const auto mode = msg.find("mode"); mode != msg.end() && !mode->is_null()) {
    static const std::regex mode_re("[a-z0-9_]{1,32}");
    if (!mode->is_string() || !std::regex_match(mode->get<std::string>(), mode_re))
      throw ProtocolError("estimate: /mode: expected 1-32 characters of [a-z0-9_], got " + json_brief(*mode));
    e.mode_label = mode->get<std::string>();
    e.mode = mode_of(e.mode_label);
  }
  if (const auto c = msg.find("compute_ms"); c != msg.end() && !c->is_null()) {
    const double ms = finite_number(*c, "estimate: /compute_ms");
    if (ms < 0) throw ProtocolError("estimate: /compute_ms: expected the client's own milliseconds for this frame (>= 0), got " + json_brief(*c));
    e.compute_ms = ms;
  }
  if (const auto extra = msg.find("extra"); extra != msg.end() && !extra->is_null()) {
    if (!extra->is_object() || extra->size() > 32) throw ProtocolError("estimate: /extra: expected an object of at most 32 numbers, got " + json_brief(*extra));
    static const std::regex key_re("[A-Za-z0-9_]{1,32}");
    for (auto it = extra->begin(); it != extra->end(); ++it) {
      if (!std::regex_match(it.key(), key_re)) throw ProtocolError("estimate: /extra: key \"" + it.key() + "\": expected 1-32 characters of [A-Za-z0-9_]");
      // frames.csv has these columns already; an extra of the same name would make it ambiguous.
      static const char* const kColumns[] = {"t", "robot", "gt_x", "gt_y", "gt_theta", "est_x", "est_y", "est_theta", "err_x", "err_y",
                                             "err_theta", "err_pos", "valid", "mode", "camera_ok", "line_points", "match_error",
                                             "contact", "exposure_ms", "gain"};
      for (const char* c : kColumns)
        if (it.key() == c) throw ProtocolError("estimate: /extra: key \"" + it.key() + "\" is a column of frames.csv already; choose another name");
      e.extra[it.key()] = finite_number(it.value(), "estimate: /extra/" + it.key());
    }
  }
  return e;
}

// At most this many particles or points an estimate: what a viewer can draw (a client's own set is
// usually larger; it sends a subsample).
constexpr std::size_t kMaxDebugItems = 10000;

DebugView ExternalLocalizer::parse_debug(const Json& msg) {
  DebugView v;
  const auto rows = [&](const char* key, std::size_t width, const std::function<void(const Json&)>& add) {
    const auto it = msg.find(key);
    if (it == msg.end() || it->is_null()) return;
    if (!it->is_array() || it->size() > kMaxDebugItems)
      throw ProtocolError(std::string("estimate: /") + key + ": expected an array of at most " + std::to_string(kMaxDebugItems) + " rows, got " +
                          json_brief(*it));
    for (std::size_t i = 0; i < it->size(); ++i) {
      const Json& r = (*it)[i];
      const std::string at = std::string("estimate: /") + key + "/" + std::to_string(i);
      if (!r.is_array() || r.size() != width) throw ProtocolError(at + ": expected " + std::to_string(width) + " numbers, got " + json_brief(r));
      for (std::size_t j = 0; j < width; ++j) (void)finite_number(r[j], at + "/" + std::to_string(j));
      add(r);
    }
  };
  rows("particles", 4, [&](const Json& r) {
    if (r[3].get<double>() < 0) throw ProtocolError("estimate: /particles: a weight below 0: " + json_brief(r));
    v.particles.push_back({r[0].get<double>(), r[1].get<double>(), r[2].get<double>(), r[3].get<double>()});
  });
  rows("points", 2, [&](const Json& r) { v.points.emplace_back(r[0].get<double>(), r[1].get<double>()); });
  return v;
}

DebugView ExternalLocalizer::debug_view(std::size_t max_particles) const {
  DebugView v;
  v.points = debug_.points;
  for (const std::size_t i : even_stride(debug_.particles.size(), max_particles)) v.particles.push_back(debug_.particles[i]);
  return v;
}

Json blob_json(const Blob& b) {
  const char* colour = b.colour == kYellow ? "yellow" : b.colour == kBlue ? "blue" : b.colour == kRed ? "red" : "unknown";
  return {{"colour", colour}, {"kind", kind_name(b.kind)}, {"bearing", b.bearing}, {"left_bearing", b.left_bearing},
          {"right_bearing", b.right_bearing}, {"distance", b.has_distance ? Json(b.distance) : Json(nullptr)},
          {"area_px", b.area_px}, {"left_occluded", b.left_occluded}, {"right_occluded", b.right_occluded}};
}

Json ExternalLocalizer::frame_json(long long k, const Observations& obs, const Odometry& odometry, std::optional<double> heading) {
  Json pts = Json::array();
  pts.get_ref<Json::array_t&>().reserve(obs.line_points.size());
  for (const auto& p : obs.line_points) pts.push_back(Json::array({p.x(), p.y()}));
  Json blobs = Json::array();
  for (const auto& b : obs.blobs) blobs.push_back(blob_json(b));
  return {{"type", "frame"},
          {"k", k},
          {"t", obs.t},
          {"odometry", {odometry.delta.x, odometry.delta.y, odometry.delta.theta}},
          {"heading", heading ? Json(*heading) : Json(nullptr)},
          {"camera_ok", obs.camera_ok},
          {"line_points", std::move(pts)},
          {"blobs", std::move(blobs)}};
}

ExternalLocalizer::ExternalLocalizer(ExternalConfig cfg, Session session) : cfg_(std::move(cfg)), session_(std::move(session)) {
  files_ = client_files(cfg_);
  ProcessSpec spec;
  spec.program = cfg_.program;
  spec.argv = cfg_.command;
  spec.cwd = cfg_.cwd;
  spec.env = cfg_.env;
  spec.env["OMNILOC_PROTOCOL"] = kProtocol;
  spec.stderr_path = session_.log_dir + "/client_r" + std::to_string(session_.robot) + ".stderr.log";
  try {
    proc_ = std::make_unique<ClientProcess>(spec);
  } catch (const RuntimeFailure& e) {
    throw RuntimeFailure("external localizer (robot " + std::to_string(session_.robot) + "): " + e.what());
  }
  const Json hello{{"type", "hello"},
                   {"protocol", kProtocol},
                   {"omniloc", session_.omniloc_version},
                   {"robot", session_.robot},
                   {"scenario", session_.scenario},
                   {"camera_rate_hz", session_.camera_rate_hz},
                   {"duration_s", session_.duration_s},
                   {"hello_timeout_s", cfg_.hello_timeout_s},
                   {"frame_timeout_s", cfg_.frame_timeout_s},
                   {"exit_timeout_s", cfg_.exit_timeout_s},
                   {"params", cfg_.params},
                   {"field", session_.field},
                   {"camera", session_.camera},
                   {"vision", {{"line_points", true}, {"blobs", session_.blobs}}}};
  const auto deadline = after(cfg_.hello_timeout_s);
  send(encode_message(hello), deadline, "hello");
  const Message ready = receive(deadline, "ready", "no ready within " + fmt_s(cfg_.hello_timeout_s) + " s");
  try {
    const Ready r = parse_ready(ready.header, session_.reserved_names);
    name_ = r.name;
    version_ = r.version;
    needs_start_pose_ = r.needs_start_pose;
    wants_image_ = r.wants_image;
  } catch (const ProtocolError& e) {
    fail(e.what());
  }
  stage_ = "before frame 0";
}

ExternalLocalizer::~ExternalLocalizer() {
  if (proc_ && !finished_) proc_->terminate();
}

Json ExternalLocalizer::provenance() const {
  return {{"protocol", kProtocol}, {"command", cfg_.command}, {"cwd", cfg_.cwd}, {"name", name_}, {"version", version_}, {"files", files_}};
}

void ExternalLocalizer::fail(const std::string& reason) {
  std::string where = "external localizer \"" + (name_.empty() ? cfg_.command[0] : name_) + "\" (robot " + std::to_string(session_.robot) + "), ";
  where += k_ >= 0 ? "frame " + std::to_string(k_) : stage_;
  std::string msg = where + ": " + reason;
  if (proc_) {
    proc_->terminate();
    const std::string tail = proc_->stderr_tail(20);
    msg += tail.empty() ? "\n  (the client wrote nothing to stderr)" : "\n  last lines of the client's stderr:\n    " + std::regex_replace(tail, std::regex("\n"), "\n    ");
  }
  finished_ = true;
  throw RuntimeFailure(msg);
}

void ExternalLocalizer::send(const std::string& bytes, Clock::time_point deadline, const char* what) {
  ClientProcess::Io io;
  try {
    io = proc_->write_all(bytes, deadline, reader_);
  } catch (const RuntimeFailure& e) {
    fail(e.what());
  }
  if (io == ClientProcess::Io::kOk) return;
  if (io == ClientProcess::Io::kTimeout) fail(std::string("the client did not read the ") + what + " message in time (stalled)");
  // The client closed its stdin: it is exiting or has exited.
  const auto st = proc_->wait_exit(Clock::now() + std::chrono::milliseconds(500));
  fail(st ? describe_wait_status(*st) + " before " + what : std::string("closed its stdin before ") + what);
}

Message ExternalLocalizer::receive(Clock::time_point deadline, const char* expected, const std::string& waiting_for) {
  std::optional<Message> m;
  ClientProcess::Io io;
  try {
    io = proc_->read_message(deadline, reader_, m);
  } catch (const ProtocolError& e) {
    fail(e.what());
  } catch (const RuntimeFailure& e) {
    fail(e.what());
  }
  if (io == ClientProcess::Io::kTimeout) fail(waiting_for);
  if (io == ClientProcess::Io::kClosed) {
    const auto st = proc_->wait_exit(Clock::now() + std::chrono::milliseconds(500));
    fail(st ? describe_wait_status(*st) + (reader_.pending() ? " in the middle of a message" : "")
            : std::string("closed its stdout"));
  }
  if (m->type() != expected) fail(std::string("expected ") + expected + ", got " + (m->type().empty() ? json_brief(m->header) : "\"" + m->type() + "\""));
  return std::move(*m);
}

void ExternalLocalizer::reset(const std::optional<Pose2>& start) {
  if (finished_) throw RuntimeFailure("external localizer \"" + name_ + "\": reset after the run ended");
  // Seeds below 2^53 are exact in every JSON parser (a JavaScript number, a Perl NV).
  const std::uint64_t seed = session_.seed & ((std::uint64_t{1} << 53) - 1);
  const Json msg{{"type", "reset"}, {"seed", seed}, {"start", start ? Json::array({start->x, start->y, start->theta}) : Json(nullptr)}};
  k_ = -1;
  stage_ = "reset";
  send(encode_message(msg), after(cfg_.frame_timeout_s), "reset");
  stage_ = "before frame 0";
}

Estimate ExternalLocalizer::update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) {
  ++k_;
  const auto deadline = after(cfg_.frame_timeout_s);
  const Json frame = frame_json(k_, obs, odometry, heading);
  std::vector<BinaryPart> parts;
  if (wants_image_) {
    if (!obs.image || obs.image->empty()) fail("the client asked for images, but this frame has none (the scenario renders no camera)");
    const Image& im = *obs.image;
    parts.push_back({"image", "uint8", {im.height, im.width, 3},
                     std::string_view(reinterpret_cast<const char*>(im.rgb.data()), im.rgb.size())});
  }
  send(encode_message(frame, parts), deadline, "frame");
  const Message m = receive(deadline, "estimate", "no estimate for frame " + std::to_string(k_) + " within " + fmt_s(cfg_.frame_timeout_s) + " s");
  try {
    Estimate e = parse_estimate(m.header, k_);
    debug_ = parse_debug(m.header);
    return e;
  } catch (const ProtocolError& e) {
    fail(e.what());
  }
}

void ExternalLocalizer::finish() {
  if (finished_) return;
  stage_ = "after end";
  const long long last = k_;
  k_ = -1;
  const auto deadline = after(cfg_.exit_timeout_s);
  send(encode_message(Json{{"type", "end"}}), deadline, "end");
  proc_->close_stdin();
  const auto st = proc_->wait_exit(deadline);
  if (!st) fail("did not exit within " + fmt_s(cfg_.exit_timeout_s) + " s of end (after frame " + std::to_string(last) + ")");
  if (!WIFEXITED(*st) || WEXITSTATUS(*st) != 0) fail(describe_wait_status(*st) + " after end");
  finished_ = true;
}

}  // namespace omniloc::external
