#pragma once
// The calibration patch of paper 002's model-free mirror calibration (after Voigtlaender et al.):
// a strip of alternating black and white stripes laid on the carpet along a ray from the robot
// centre. Its 15 stripe boundaries ("edges") lie at these ground distances from the robot centre.
// The renderer draws it (sim); the calibration procedure (localization/vision) knows only these
// distances and finds the edges in the image with Canny.
#include <array>

namespace omniloc::calibration_patch {

/// Ground distances of the 15 edges from the robot centre, metres, increasing. Denser near the
/// robot where the mirror compresses least; out to 8 m, beyond which line points are not used.
inline constexpr std::array<double, 15> kEdgeDistances = {0.35, 0.50, 0.70, 0.95, 1.25, 1.60, 2.00, 2.50,
                                                          3.00, 3.60, 4.30, 5.10, 6.00, 7.00, 8.00};
/// Width of the strip across the ray, metres (wide enough to stay several pixels wide at 8 m).
inline constexpr double kStripWidth = 0.40;
/// The stripe between edge i and i+1 is white for even i, black for odd i; green carpet outside.
inline constexpr bool stripe_is_white(int i) { return i % 2 == 0; }
/// Directions (robot-frame bearings) in which the patch is imaged while the robot turns: every 10 deg.
inline constexpr int kDirections = 36;

}  // namespace omniloc::calibration_patch
