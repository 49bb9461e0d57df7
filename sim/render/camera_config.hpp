#pragma once
// Panoramic camera configuration (scenario key "camera"). Units: pixels, metres, radians (degrees
// in the JSON where named *_deg), milliseconds for exposure.
#include <algorithm>
#include <string>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/messages.hpp"

namespace omniloc::sim {

struct CameraConfig {
  int width = 640, height = 640;        ///< image size, pixels
  double mount_height = 0.75;           ///< mirror viewpoint above the floor, metres
  std::string mirror = "nubot_composite";
  double rim_fraction = 0.49;           ///< mirror rim radius as a fraction of min(width, height)
  Eigen::Vector2d centre_offset_px{0.0, 0.0};  ///< mirror axis offset from the image centre, pixels
  double mirror_tilt = 0.0;             ///< fixed mirror tilt about the robot's x axis, radians
  /// Body tilt on the suspension per unit of drive acceleration, radians per m/s^2 (0: a rigid robot).
  double tilt_per_accel = 0.0;
  /// Defocus blur-circle diameter at the mirror's rim, image pixels (0: sharp everywhere), and the
  /// image radius in focus, as a fraction of the rim radius (docs/camera.md "Optical blur").
  double optical_blur_px = 0.0;
  double focus_radius_fraction = 0.5;
  /// Integrate the image over the exposure: this robot's rotation as a polar smear, translations by sub-frames.
  bool motion_blur = false;
  double latency = 0.0;                 ///< seconds between exposure and the odometry it is paired with
  double vibration_std = 0.0052;        ///< per-frame roll/pitch std, radians (0.3 deg: a robot on carpet)
  double read_noise = 1.5;              ///< DN at gain 18
  double shot_noise = 0.35;             ///< DN^(1/2): shot-noise std = shot_noise * sqrt(value * gain / 18)
  std::string backend = "osmesa";       ///< "osmesa" or "egl" (OMNILOC_GL_BACKEND overrides the JSON; egl_device.hpp)
  std::string quality = "default";      ///< "low" (coarse floor mesh), "default", "high" (2x2 supersampling)
  CameraSettings initial;               ///< settings of the first frame
  double exposure_min = 1.0, exposure_max = 60.0;  ///< ms
  double gain_min = 1.0, gain_max = 60.0;
  /// The mirror's rim radius in the image, pixels (rim_fraction x the smaller side).
  double rim_px() const { return rim_fraction * std::min(width, height); }
  /// The true mirror axis in the image, pixels (the image centre plus centre_offset_px).
  Eigen::Vector2d mirror_centre_px() const { return Eigen::Vector2d(0.5 * width, 0.5 * height) + centre_offset_px; }
  /// Strict reading (unknown keys, non-positive sizes or exposure are ConfigErrors naming the path).
  static CameraConfig from_json(const Json& j, const std::string& path, Json* effective = nullptr);
  Json to_json() const;
};

}  // namespace omniloc::sim
