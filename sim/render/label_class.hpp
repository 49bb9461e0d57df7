#pragma once
// The classes a labelled render (PanoramicCamera::render_labels) writes per pixel: the camera, the
// floor mesh and the scene mesh all draw them, so they sit below all three.
#include <cstdint>

namespace omniloc::sim {

/// Classes of render_labels(), one per pixel (value in every channel).
enum LabelClass : std::uint8_t {
  kLabelUnknown = 0,
  kLabelField = 1,
  kLabelLine = 2,
  kLabelBall = 3,
  kLabelObstacle = 4,
  kLabelBody = 5,
  kLabelYellow = 6,
  kLabelBlue = 7,
  kLabelRed = 8,
  kLabelFloorOutside = 9,
  kLabelWall = 10,
  kLabelGoal = 11,
};

}  // namespace omniloc::sim
