#pragma once
// Occlusion masks (paper 002, table 1): black sectors drawn into the panorama, as when something
// covers part of the mirror. Sectors are given as robot-frame bearings (radians, anticlockwise from
// the robot's forward axis), either fixed to the robot (they turn with it) or fixed in the world.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/json_reader.hpp"
#include "core/messages.hpp"

namespace omniloc::sim {

struct Sector {
  double start = 0.0;  ///< radians, first bearing covered
  double width = 0.0;  ///< radians, anticlockwise extent (0, 2 pi]
};

struct OcclusionMask {
  std::vector<Sector> sectors;
  bool world_fixed = false;  ///< false: sectors turn with the robot; true: fixed world bearings
  double fraction() const;
  /// The sectors as robot-frame bearings for a robot with world heading `theta`.
  std::vector<Sector> robot_frame(double theta) const;

  /// {"fraction": f, "sectors": n, "start_deg": a, "frame": "robot"|"world"} (n equal sectors spread
  /// evenly, together covering f) or {"sectors": [[start_deg, width_deg], ...], "frame": ...}.
  /// Errors: fraction outside [0, 1], overlapping or empty sectors, each naming the JSON path.
  static OcclusionMask from_json(const Json& j, const std::string& path);
};

/// Paints the sectors black in `image`, from the image centre outwards. The image convention is the
/// camera's: the robot's forward axis points up in the image (v decreasing), robot-left points left.
void paint_sectors(Image& image, const Eigen::Vector2d& centre_px, const std::vector<Sector>& robot_frame_sectors);

/// Bearing b (robot frame) -> unit direction in the image (u right, v down).
inline Eigen::Vector2d image_direction(double bearing) { return {-std::sin(bearing), -std::cos(bearing)}; }

}  // namespace omniloc::sim
