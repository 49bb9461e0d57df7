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
  double radius = 0.26;     ///< footprint radius, metres (MSL robots ~0.52 m across)
  double height = 0.8;      ///< metres
};

struct BallState {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< world frame, metres
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  ///< m/s
  double radius = 0.11;                                ///< metres (0.22 m ball)
};

/// Illumination of the scene (issue: lighting). 1.0 = the normal artificial light of the hall.
struct SunPatch {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< world frame, metres, on the carpet
  Eigen::Vector2d half_size = {1.0, 0.5};            ///< metres
  double strength = 3.0;                             ///< added illumination, in units of the normal level
};
struct Lighting {
  double level = 1.0;            ///< global artificial level (0 = dark, 1 = normal)
  std::vector<SunPatch> sun;     ///< bright sharp patches on the carpet
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
