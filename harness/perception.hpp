#pragma once
// Perception: the robot-side path from the simulated world to Observations. The camera renders the
// panorama (sim), the vision front end extracts line points from the pixels (localization); the
// localizer only ever gets the Observations. Scenarios whose localizer needs no vision skip it.
#include <memory>
#include <optional>

#include "core/messages.hpp"
#include "core/rng.hpp"
#include "harness/scenario.hpp"
#include "localization/localizer.hpp"
#include "localization/vision/calibration_map.hpp"
#include "sim/occlusion.hpp"
#include "sim/render/gl_device_info.hpp"
#include "sim/world_state.hpp"

namespace omniloc::harness {

/// What the harness imposes on one camera frame (scripted events), beyond the world itself.
struct FrameConditions {
  bool covered = false;                   ///< lens covered (kidnapping): black image
  std::vector<sim::Sector> occlusion;     ///< black sectors, robot-frame bearings
};

struct PerceptionOutput {
  Observations obs;
  std::shared_ptr<const Image> image;  ///< the rendered frame (null when nothing was rendered)
  CameraSettings settings;             ///< settings the image was taken with
  double render_ms = 0.0;              ///< wall time, for timing.csv only (never in summaries)
  double vision_ms = 0.0;
  bool stop_robot = false;             ///< the robot must stand still (camera adjusting, paper 002)
  std::vector<std::string> warnings;   ///< written to events.jsonl
  std::vector<std::string> notes;      ///< camera control events (exposure search), written to events.jsonl
  double entropy = -1.0;               ///< image entropy (nats) when it was computed, else -1
};

class Perception {
 public:
  virtual ~Perception() = default;
  /// One camera frame of robot `robot_id` under the scripted conditions.
  virtual PerceptionOutput observe(const sim::WorldState& world, int robot_id, double t, const FrameConditions& cond) = 0;
  /// The image -> robot-frame calibration the vision uses (null when nothing is rendered).
  virtual const CalibrationMap* calibration_map() const { return nullptr; }
  /// Whether observations carry coloured blobs.
  virtual bool detects_blobs() const { return false; }
  /// The GL device the camera renders on (provenance); none without a camera.
  virtual std::optional<sim::GlDeviceInfo> render_device() const { return std::nullopt; }
};

/// No camera: empty observations (for localizers that need no vision, e.g. odometry_only).
class NoPerception : public Perception {
 public:
  PerceptionOutput observe(const sim::WorldState&, int, double t, const FrameConditions& cond) override {
    PerceptionOutput o;
    o.obs.t = t;
    o.obs.camera_ok = !cond.covered;
    return o;
  }
};

}  // namespace omniloc::harness
