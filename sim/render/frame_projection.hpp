#pragma once
// Where the camera is in one frame and how a world point lands in render space, shared by the scene
// mesh and the floor mesh so that both project their vertices with the same arithmetic (inline: a
// frame projects tens of thousands of vertices, and a call into another file per vertex would cost).
//
// Frames: world (metres, radians); robot (x forward, y left, z up, metres); camera (the robot frame
// turned by the mirror's tilt and vibration, origin at the mirror's viewpoint); render space (the
// image's pixels times the supersampling factor: x right, y down; z = minus the distance in metres,
// for the depth test).
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "core/pose2.hpp"
#include "sim/render/mirror.hpp"

namespace omniloc::sim {

struct FrameProjection {
  /// `R`: camera-to-robot rotation; `centre`: the mirror axis in the image, pixels.
  FrameProjection(const MirrorProfile& mirror_, const Eigen::Vector2d& centre_, int ss_, const Pose2& pose_,
                  double mount_height, const Eigen::Matrix3d& R_)
      : mirror(mirror_), centre(centre_), ss(ss_), pose(pose_), h(mount_height), c(std::cos(pose_.theta)),
        s(std::sin(pose_.theta)), R(R_), Rt(R_.transpose()), eye(pose_.x, pose_.y, mount_height) {}

  /// Render-space x, y and z of world point `wp`.
  void operator()(const Eigen::Vector3d& wp, float* out) const {
    const double dx = wp.x() - pose.x, dy = wp.y() - pose.y;
    const Eigen::Vector3d q = Rt * Eigen::Vector3d(c * dx + s * dy, -s * dx + c * dy, wp.z() - h);
    const double rho = std::max(std::hypot(q.x(), q.y()), 1e-9);
    const double k = mirror.radius(std::atan2(q.z(), rho)) / rho;  // bearing b: (cos b, sin b) = (q.x, q.y) / rho
    out[0] = static_cast<float>((centre.x() - k * q.y()) * ss);
    out[1] = static_cast<float>((centre.y() - k * q.x()) * ss);
    out[2] = static_cast<float>(-std::min(999.0, q.norm()));
  }

  const MirrorProfile& mirror;
  Eigen::Vector2d centre;  // pixels
  int ss;                  // supersampling factor
  Pose2 pose;              // the robot, world frame
  double h;                // mount height, metres
  double c, s;             // cos and sin of pose.theta
  Eigen::Matrix3d R, Rt;   // camera to robot, and back
  Eigen::Vector3d eye;     // the camera, world frame (vibration aside)
};

}  // namespace omniloc::sim
