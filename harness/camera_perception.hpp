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

class CameraPerception : public Perception {
 public:
  CameraPerception(const Scenario& s, std::uint64_t seed);
  PerceptionOutput observe(const sim::WorldState& world, int robot_id, double t, const FrameConditions& cond) override;
  const sim::PanoramicCamera& camera() const { return *camera_; }
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

}  // namespace omniloc::harness
