#pragma once
// What flows from the simulated robot to the localization side: exactly what a real robot has
// (images, odometry, compass, team messages), never ground truth.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/pose2.hpp"

namespace omniloc {

/// Camera settings the localization side may change every frame (paper 002: only these two).
struct CameraSettings {
  double exposure_ms = 18.0;  ///< exposure time, milliseconds (paper 002: 18 under normal light)
  double gain = 18.0;         ///< analogue gain, camera units (paper 002: 18 under normal light)
};

/// An 8-bit RGB image, row-major, 3 bytes per pixel, image frame: u right, v down, origin top-left.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
  bool empty() const { return width == 0 || height == 0; }
  std::uint8_t* row(int v) { return rgb.data() + static_cast<std::size_t>(v) * width * 3; }
  const std::uint8_t* row(int v) const { return rgb.data() + static_cast<std::size_t>(v) * width * 3; }
};

/// Wheel odometry: the motion since the previous reading, in the robot frame at the previous reading.
struct Odometry {
  double t = 0.0;  ///< seconds
  Pose2 delta;     ///< metres, radians
};

/// Absolute heading sensor (compass or MTi/AHRS), world frame.
struct HeadingReading {
  double t = 0.0;        ///< seconds
  double heading = 0.0;  ///< radians
};

}  // namespace omniloc
