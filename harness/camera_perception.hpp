#pragma once
// The full robot-side path for one camera frame: the simulated camera renders the panorama (sim),
// scripted occlusion is painted into it, and the vision front end (colour table, radial scan lines,
// calibration map: localization/vision) turns pixels into robot-frame line points.
#include <map>
#include <memory>

#include "harness/perception.hpp"
#include "localization/vision/blobs.hpp"
#include "localization/vision/calibration_map.hpp"
#include "localization/vision/colour_table.hpp"
#include "localization/vision/exposure_control.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::harness {

/// Scenario key "vision": where the calibration map and colour table come from, scan-line parameters.
struct VisionConfig {
  std::string calibration = "auto";   ///< a map file, or "auto" (cached calibration run)
  std::string colour_table = "auto";  ///< a table file, or "auto"
  ScanLineParams scan;
  ExposureParams exposure;            ///< key "exposure_control" (camera ranges come from "camera")
  /// "blobs": {"detect": "auto" | "on" | "off", ...BlobParams}. auto: when the field has coloured
  /// goals or landmarks. Edge colours default to the colours of the field's coloured goals.
  std::string blobs_detect = "auto";
  BlobParams blobs;
  bool blob_edge_colours_given = false;
  /// Whether blob detection runs on `field`.
  bool detect_blobs(const Field& field) const {
    return blobs_detect == "on" || (blobs_detect == "auto" && field.has_coloured_objects());
  }
  static VisionConfig from_json(const Json& j, const std::string& path, Json* effective = nullptr);
};

/// The one assembly of camera + calibration map + colour table + detectors (the run loop, `render`
/// and the experiments all build theirs here, so they see and process pixels alike).
class CameraPerception : public Perception {
 public:
  /// `seed` names the calibration and colour-table runs ("auto") and the camera noise streams.
  CameraPerception(const sim::CameraConfig& camera, const Field& field, const VisionConfig& vision, std::uint64_t seed);
  /// The scenario's camera, field and vision configuration.
  CameraPerception(const Scenario& s, std::uint64_t seed);
  PerceptionOutput observe(const sim::WorldState& world, int robot_id, double t, const FrameConditions& cond) override;
  const sim::PanoramicCamera& camera() const { return *camera_; }
  sim::PanoramicCamera& camera() { return *camera_; }
  std::optional<sim::GlDeviceInfo> render_device() const override { return camera_->device(); }
  const CalibrationMap& calibration() const { return map_; }
  const CalibrationMap* calibration_map() const override { return &map_; }
  bool detects_blobs() const override { return blob_detector_ != nullptr; }
  const ColourTable& colour_table() const { return table_; }
  /// The exposure controller's parameters with the camera's exposure and gain ranges filled in.
  const ExposureParams& exposure_params() const { return exposure_; }
  const LineDetector& detector() const { return *detector_; }
  /// Null when the scenario does not detect blobs.
  const BlobDetector* blob_detector() const { return blob_detector_.get(); }

 private:
  std::unique_ptr<sim::PanoramicCamera> camera_;
  CalibrationMap map_;
  ColourTable table_;
  std::unique_ptr<LineDetector> detector_;
  std::unique_ptr<BlobDetector> blob_detector_;
  std::uint64_t seed_;
  std::map<int, Rng> rngs_;
  std::map<int, CameraSettings> settings_;
  ExposureParams exposure_;
  std::map<int, ExposureController> controllers_;
};

/// Builds the perception a scenario needs: this camera and vision when its localizer needs vision,
/// else NoPerception (perception.hpp).
std::unique_ptr<Perception> make_perception(const Scenario& s, bool needs_vision, std::uint64_t seed);

}  // namespace omniloc::harness
