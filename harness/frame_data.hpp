#pragma once
// One camera frame of a run: what every localized robot's localizer is given (odometry, heading,
// observations) and what scoring needs beside it (the true pose, contact). The type the run loop
// reads from a FrameSource (harness/frame_source.hpp) and a recording stores line by line
// (harness/recording/format/frame_codec.hpp); it knows neither, so the recording format sits below
// the running code.
//
// Units: seconds, metres, radians; poses in the world frame, observations in the robot frame.
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "core/pose2.hpp"
#include "localization/localizer.hpp"

namespace omniloc::harness {

/// One localized robot at one camera frame.
struct RobotFrame {
  int id = 0;
  // What the robot's localizer is given.
  Odometry odometry;              ///< since the previous frame, robot frame of the previous frame
  std::optional<double> heading;  ///< compass / MTi, world frame
  Observations obs;               ///< t, camera_ok, line points, blobs, image (when rendered or recorded)
  // What the run records beside it.
  bool covered = false;                    ///< lens covered: a localizer without vision still sees camera_ok = false
  std::optional<CameraSettings> settings;  ///< the settings an image was taken with (none when nothing was rendered)
  bool stop_robot = false;                 ///< perception asked the robot to stand still from the next step
  std::vector<std::string> events;         ///< events.jsonl lines of this robot's perception (warnings, camera, pause)
  double render_ms = 0.0, vision_ms = 0.0; ///< wall time (timing.csv only)
  // Scoring only: never given to a localizer.
  std::optional<Pose2> truth;  ///< none in a log without ground truth
  bool contact = false;
};

/// One camera frame of every localized robot.
struct FrameData {
  long long k = 0;
  double t = 0.0;                   ///< seconds: the physics step the frame was taken at
  std::vector<std::string> events;  ///< events.jsonl lines of the scenario's events applied before this frame
  std::vector<RobotFrame> robots;   ///< in the scenario's order of localized robots
};

}  // namespace omniloc::harness
