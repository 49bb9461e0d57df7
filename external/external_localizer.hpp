#pragma once
// The Localizer that speaks olp/1 (docs/protocol.md) to a user's program: one client process per
// localized robot, lock-step (one frame outstanding), every wait bounded by a time-out, every
// violation a RuntimeFailure that names the robot, the frame, the reason and the client's stderr.
#include <memory>
#include <string>
#include <vector>

#include "external/client_process.hpp"
#include "external/external_config.hpp"
#include "localization/localizer.hpp"

namespace omniloc::external {

/// What the host tells the client in hello beyond the configuration (built by the harness).
struct Session {
  int robot = 0;
  std::string scenario;
  std::string omniloc_version;
  double camera_rate_hz = 30.0;
  double duration_s = 0.0;
  Json field = Json::object();    ///< docs/protocol.md "field"
  Json camera = Json::object();   ///< docs/protocol.md "camera" (size, mirror centre, calibration)
  bool blobs = false;             ///< whether frames can carry blobs
  std::string log_dir;            ///< the client's stderr log goes here
  std::uint64_t seed = 0;         ///< the localizer's seed (sent in reset, reduced below 2^53)
  std::vector<std::string> reserved_names;  ///< built-in localizer names a client may not take
};

/// One blob as olp/1's frame.blobs holds it (docs/protocol.md); recordings store blobs the same way.
Json blob_json(const Blob& blob);

class ExternalLocalizer : public Localizer {
 public:
  /// Starts the client, sends hello and waits for ready (hello_timeout_s). Throws RuntimeFailure.
  ExternalLocalizer(ExternalConfig cfg, Session session);
  ~ExternalLocalizer() override;  ///< ends the client's process group if finish() was not reached

  std::string type() const override { return "external"; }
  /// The name results carry: the entry's "label" when the user gave one, else ready.name (never
  /// empty once ready was read). One rule for summary.json, the aggregate and the report.
  std::string name() const override { return cfg_.label.empty() ? name_ : cfg_.label; }
  bool wants_start_pose() const override { return needs_start_pose_; }
  bool wants_image() const { return wants_image_; }
  Json provenance() const override;
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;
  /// Sends end and waits for exit status 0 (exit_timeout_s). Throws RuntimeFailure otherwise.
  void finish() override;

  /// The frame message for `obs` (no image part), as sent; exposed for tests and benchmarks.
  static Json frame_json(long long k, const Observations& obs, const Odometry& odometry, std::optional<double> heading);
  /// Reads an estimate message strictly; throws ProtocolError with the JSON path on a bad field.
  static Estimate parse_estimate(const Json& msg, long long expected_k);
  /// The estimate's optional "particles" and "points" (docs/protocol.md section 6), read strictly:
  /// what the client asks the run viewer to draw.
  static DebugView parse_debug(const Json& msg);
  /// The last estimate's particles and points, at most `max_particles` particles.
  DebugView debug_view(std::size_t max_particles) const override;
  /// Reads a ready message strictly (name, version, flags).
  struct Ready {
    std::string name, version;
    bool needs_start_pose = false, wants_image = false;
  };
  static Ready parse_ready(const Json& msg, const std::vector<std::string>& reserved_names);

 private:
  [[noreturn]] void fail(const std::string& reason);
  void send(const std::string& bytes, Clock::time_point deadline, const char* what);
  Message receive(Clock::time_point deadline, const char* expected, const std::string& waiting_for);

  ExternalConfig cfg_;
  Session session_;
  std::unique_ptr<ClientProcess> proc_;
  MessageReader reader_;
  std::string name_, version_;
  bool needs_start_pose_ = false, wants_image_ = false;
  long long k_ = -1;           // the frame being sent / awaited; -1 before frame 0
  std::string stage_ = "before ready";
  bool finished_ = false;
  Json files_;
  DebugView debug_;  // of the last estimate
};

}  // namespace omniloc::external
