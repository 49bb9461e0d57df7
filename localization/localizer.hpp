#pragma once
// The one interface every localizer implements. A localizer sees only robot-side data:
// line points / blobs from the vision front end (robot frame), odometry and an optional absolute
// heading. It never sees the simulator.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/messages.hpp"
#include "core/pose2.hpp"
#include "localization/vision/colour_table.hpp"

namespace omniloc {

/// A coloured region (cube, post, goal) found by blob detection (localization/vision/blobs.hpp),
/// or one edge of such a region.
///
/// Frames and units: bearings are robot-frame directions in radians, anticlockwise from the robot's
/// forward (x) axis, wrapped to (-pi, pi]; distances are metres on the floor from the robot centre
/// (through the calibration map). "Left" is anticlockwise: seen from the robot, the left edge of a
/// region is the one at the larger bearing.
struct Blob {
  enum class Kind : std::uint8_t {
    kRegion,     ///< the whole region; bearing = middle of its angular extent
    kLeftEdge,   ///< its anticlockwise edge (emitted for goal colours only); bearing = the edge
    kRightEdge,  ///< its clockwise edge (goal colours only)
  };
  ColourClass colour = kUnknown;  ///< kYellow, kBlue, kRed (colour_table.hpp)
  Kind kind = Kind::kRegion;
  double bearing = 0.0;        ///< radians, see above
  double left_bearing = 0.0;   ///< radians: the region's anticlockwise edge (same for all kinds)
  double right_bearing = 0.0;  ///< radians: the region's clockwise edge
  /// Metres from the robot centre to the region's ground contact nearest the robot (for an edge:
  /// nearest along that edge); valid only when has_distance (beyond the calibrated range it is not).
  double distance = 0.0;
  bool has_distance = false;
  int area_px = 0;             ///< pixels in the region
  /// True when the region touches an obstacle (black) pixel or the image border across an edge:
  /// it may be cut off there, so that edge (and the middle bearing) may be wrong.
  bool left_occluded = false, right_occluded = false;
};

/// What the vision front end extracted from one image.
struct Observations {
  double t = 0.0;        ///< seconds
  bool camera_ok = true; ///< false when the image was unusable (covered, black, missing)
  /// White line points in the robot frame, metres (x forward, y left).
  std::vector<Eigen::Vector2d> line_points;
  /// Coloured blobs (regions and goal edges); empty unless blob detection ran (the scenario's
  /// "vision": {"blobs": ...}, by default whenever the field has coloured goals or landmarks).
  std::vector<Blob> blobs;
  /// The image the observations were extracted from (null when nothing was rendered). Built-in
  /// localizers use only the extracted observations; external ones may ask for the pixels.
  std::shared_ptr<const Image> image;
};

/// What a localizer is doing in a frame. Written as text (mode_name) only in frames.csv and
/// events.jsonl; code compares the enum.
enum class LocalizerMode : std::uint8_t {
  kNone,           ///< no frame yet (written as an empty field)
  kTracking,       ///< matching / MCL tracking a pose it stands behind
  kCoasting,       ///< no usable vision: odometry only, no jump
  kGlobal,         ///< searching the whole field (MCL spread out, grid search running)
  kConverged,      ///< a global search has just settled on a pose
  kConvergedWeak,  ///< grid_global: settled on the best candidate without the acceptance test
  kRestart,        ///< the wrong-localisation detector gave the pose up
  kFix,            ///< landmarks: a pose from this frame's bearings
  kOdometry,       ///< landmarks: no fix this frame, odometry since the last one
  kNoFix,          ///< landmarks: no fix yet
  kDeadReckoning,  ///< odometry_only
};

/// The mode as written in frames.csv and events.jsonl ("tracking", "converged_weak", ...).
inline const char* mode_name(LocalizerMode m) {
  switch (m) {
    case LocalizerMode::kNone: return "";
    case LocalizerMode::kTracking: return "tracking";
    case LocalizerMode::kCoasting: return "coasting";
    case LocalizerMode::kGlobal: return "global";
    case LocalizerMode::kConverged: return "converged";
    case LocalizerMode::kConvergedWeak: return "converged_weak";
    case LocalizerMode::kRestart: return "restart";
    case LocalizerMode::kFix: return "fix";
    case LocalizerMode::kOdometry: return "odometry";
    case LocalizerMode::kNoFix: return "no_fix";
    case LocalizerMode::kDeadReckoning: return "dead_reckoning";
  }
  return "";
}

/// A localizer's answer for one frame.
struct Estimate {
  Pose2 pose;                                      ///< world frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  ///< (x, y, theta), m^2 / rad^2
  bool valid = false;       ///< false until the localizer has a pose it stands behind
  LocalizerMode mode = LocalizerMode::kNone;
  double match_error = 0.0; ///< localizer-specific quality figure (lower is better)
  /// Extra numbers for frames.csv (e.g. "global_ms", "particles"), stable keys per localizer.
  std::map<std::string, double> extra;
  /// A mode word from an external localizer (docs/protocol.md); written instead of mode_name(mode)
  /// when not empty. `mode` is set too when the word is one of ours.
  std::string mode_label;
  /// An external localizer's own computation time for this frame (milliseconds, olp/1 estimate
  /// "compute_ms"), when it reports one; timing.csv writes it beside the round trip.
  std::optional<double> compute_ms;
};

/// What a localizer holds beyond its estimate, for the run viewer (`--debug-view`: view.jsonl,
/// docs/viewer.md section 4). World frame, metres and radians.
struct DebugView {
  std::vector<std::array<double, 4>> particles;  ///< [x, y, theta, weight]: a subsample of its set
  std::vector<Eigen::Vector2d> points;           ///< anything else worth drawing (match candidates...)
};

/// At most `max` of `n` items, taken at an even stride from the first (keeps the set's spread).
inline std::vector<std::size_t> even_stride(std::size_t n, std::size_t max) {
  std::vector<std::size_t> idx;
  if (n == 0 || max == 0) return idx;
  const std::size_t m = n < max ? n : max;
  idx.reserve(m);
  for (std::size_t i = 0; i < m; ++i) idx.push_back(i * n / m);
  return idx;
}

class Localizer {
 public:
  virtual ~Localizer() = default;
  /// Registry name, e.g. "matching".
  virtual std::string type() const = 0;
  /// Starts over. `start` is given to tracking localizers; global ones get nullopt and must search.
  virtual void reset(const std::optional<Pose2>& start) = 0;
  /// One frame: odometry since the previous frame, observations of this frame, optional heading
  /// (world frame, radians) from compass / MTi.
  virtual Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) = 0;
  /// The name its results carry (summary.json "localizer"): type() for built-in ones, the client's
  /// own name for an external localizer.
  virtual std::string name() const { return type(); }
  /// True when it asked for the true start pose itself (external localizers say so at start-up;
  /// built-in ones are described by the registry).
  virtual bool wants_start_pose() const { return false; }
  /// What identifies the implementation beyond the build (an external client's command, files and
  /// version); null for built-in localizers.
  virtual Json provenance() const { return nullptr; }
  /// Called once after the last frame, before the results are written; may throw RuntimeFailure
  /// (an external client that does not end cleanly fails the run).
  virtual void finish() {}
  /// What it holds after the last update(), at most `max_particles` particles (asked only with
  /// --debug-view; reading it must not change the localizer). Empty by default.
  virtual DebugView debug_view(std::size_t max_particles) const {
    (void)max_particles;
    return {};
  }
};

}  // namespace omniloc
