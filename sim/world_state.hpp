#pragma once
// A snapshot of the simulated world: ground truth. The renderer draws it; harness::Metrics scores
// against it; the localization side never sees it. World frame, metres, radians.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/pose2.hpp"

namespace omniloc::sim {

struct RobotState {
  int id = 0;
  int team = 0;             ///< 0 = the observer's team, 1 = opponents
  Pose2 pose;               ///< world frame
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< world frame, m/s
  double omega = 0.0;                                  ///< rad/s, anticlockwise
  /// What the drive's wheels push the body with over the last physics step (world frame, m/s^2);
  /// the camera turns it into the body's tilt on its suspension. Contact forces are not included.
  Eigen::Vector2d acceleration = Eigen::Vector2d::Zero();
  double radius = 0.26;     ///< footprint radius, metres (MSL robots ~0.52 m across)
  double height = 0.8;      ///< metres
};

struct BallState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< world frame, metres
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s
  double radius = 0.11;                                ///< metres (0.22 m ball)
};

/// Illumination of the scene (issue: lighting). 1.0 = the normal artificial light of the hall.
/// Light is white: the camera's auto white balance is assumed to have removed the lamps' and the
/// sun's colour temperature, so light changes a surface's brightness and (through clipping and noise)
/// its saturation, never its hue.
struct SunPatch {
  enum class Surface { kFloor, kWall };
  /// kFloor: a beam through a window: everything whose (x, y) lies in the rectangle (carpet, robots,
  /// ball standing in it) gets `strength` more light. kWall: a lit rectangle on the hall wall nearest
  /// to `centre`, `half_size.x()` along the wall and from z_min to z_max up it.
  Surface surface = Surface::kFloor;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< world frame, metres
  Eigen::Vector2d half_size = {1.0, 0.5};            ///< metres (kWall: only x, along the wall)
  double z_min = 0.0, z_max = 1.0;                   ///< kWall: metres above the floor
  double strength = 3.0;                             ///< added illumination, in units of the normal level
};
/// A lamp (or bank of lamps) of the hall. When a scenario lists lamps, the artificial light at a
/// floor point p is level * ((1 - diffuse) * sum_i state_i k_i(p) / sum_i k_i(p) + diffuse * mean_i state_i),
/// k_i = exp(-|p - c_i|^2 / (2 spread^2)): the direct part is the share of the light at p that comes
/// from lamps that are on, the diffuse part the light the ceiling and walls spread over the whole
/// hall. With every lamp on it is `level` everywhere (the light the colour table was learned under);
/// switching some off darkens their part of the hall smoothly.
struct Lamp {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< world frame, metres (under the lamp)
  double spread = 3.0;                               ///< metres, std of the lamp's footprint
  double state = 1.0;                                ///< 0 = off, 1 = on (dimmed or warming up in between)
};
struct Lighting {
  double level = 1.0;            ///< global artificial level (0 = dark, 1 = normal)
  std::vector<SunPatch> sun;     ///< bright sharp patches on the carpet and walls
  std::vector<Lamp> lamps;       ///< empty: the artificial light is `level` everywhere
  double diffuse = 0.3;          ///< share of the lamps' light spread evenly over the hall (0..1)
  /// Artificial light (without sun) at a world point, in units of the normal level.
  double artificial_at(const Eigen::Vector2d& p) const;
  /// Artificial light plus the floor sun beams covering p.
  double at(const Eigen::Vector2d& p) const;
};

/// A flat coloured rectangle lying on the carpet (calibration patches, markers).
struct FloorPatch {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< world frame, metres
  Eigen::Vector2d half_size = {0.5, 0.5};            ///< metres, along the patch's own x / y
  double angle = 0.0;                                ///< patch x axis in the world, radians
  Eigen::Vector3d reflectance = {1, 1, 1};           ///< linear RGB albedo in [0, 1]
};

struct WorldState {
  double t = 0.0;  ///< seconds
  std::vector<RobotState> robots;
  BallState ball;
  bool has_ball = true;
  Lighting lighting;
  std::vector<FloorPatch> floor_patches;
  const RobotState* robot(int id) const {
    for (const auto& r : robots)
      if (r.id == id) return &r;
    return nullptr;
  }
};

}  // namespace omniloc::sim
