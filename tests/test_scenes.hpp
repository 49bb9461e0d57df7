#pragma once
// Scenes and camera settings shared by the image tests.
#include "core/pose2.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/world_state.hpp"

namespace omniloc::testing_scenes {

/// The default camera without vibration or pixel noise: known answers need a still, clean image.
inline sim::CameraConfig quiet_camera() {
  sim::CameraConfig c;
  c.vibration_std = 0;
  c.read_noise = 0;
  c.shot_noise = 0;
  return c;
}

/// Robot 0 alone at `pose` (world frame), no ball.
inline sim::WorldState one_robot(const Pose2& pose) {
  sim::WorldState w;
  sim::RobotState r;
  r.id = 0;
  r.pose = pose;
  w.robots.push_back(r);
  w.has_ball = false;
  return w;
}

}  // namespace omniloc::testing_scenes
