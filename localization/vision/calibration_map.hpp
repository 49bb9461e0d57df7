#pragma once
// The model-free image -> robot-frame ground map of paper 002 (after Voigtlaender et al.): built
// from calibration images by omniloc calibrate, saved to a file, loaded by the pipeline. The
// localization side knows the camera only through this map, never through the simulator's mirror.
//
// Frames: image pixels (u right, v down, origin top-left corner of the image, pixel centres at
// integer + 0.5); robot frame (metres, x forward, y left) on the floor plane.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace omniloc {

class CalibrationMap {
 public:
  CalibrationMap() = default;

  int image_width() const { return width_; }
  int image_height() const { return height_; }
  /// Image centre (the mirror axis) found by calibration, pixels.
  Eigen::Vector2d centre() const { return centre_; }
  /// Largest image radius (pixels) for which the map is defined; beyond it pixels see no floor.
  double max_radius() const { return max_radius_; }
  /// Ground distance (metres) for an image radius at a given image angle; nullopt outside the map.
  std::optional<double> ground_distance(double radius_px, double image_angle) const;
  /// Robot-frame floor point seen at pixel (u, v); nullopt where the map is undefined.
  std::optional<Eigen::Vector2d> to_robot(double u, double v) const;
  /// Inverse: image radius (pixels) at which a floor point at `distance` metres and robot-frame
  /// bearing appears; nullopt beyond the calibrated range. Used to size line-width windows.
  std::optional<double> radius_for_distance(double distance, double bearing) const;

  /// Tables: for each of `directions` image angles (evenly spaced from 0), the increasing image radii
  /// of the calibration marks and their ground distances (metres). Interpolated by Lagrange
  /// polynomials along the radius and linearly... see calibration_map.cpp for the exact scheme.
  void set_tables(int width, int height, Eigen::Vector2d centre, double robot_heading_offset,
                  std::vector<std::vector<double>> radii_px, std::vector<std::vector<double>> distances_m);

  /// Text/JSON file round trip. load() throws omniloc::ConfigError naming the file on a bad or missing file.
  void save(const std::string& path) const;
  static CalibrationMap load(const std::string& path);

 private:
  int width_ = 0, height_ = 0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double heading_offset_ = 0.0;  ///< image angle of the robot's forward axis, radians
  double max_radius_ = 0.0;
  std::vector<std::vector<double>> radii_, distances_;
};

}  // namespace omniloc
