#pragma once
// Image entropy for camera auto-adjustment (paper 002, section on lighting): the sum over the R, G
// and B channels of -sum_k p_k ln p_k over each channel's 256-bin histogram, in nats. A constant
// image has entropy 0, uniform noise about 3 ln 256 = 16.64. The image frame: u right, v down.
#include <Eigen/Core>

#include "core/messages.hpp"

namespace omniloc {

/// Entropy (nats) of the pixels within `outer_radius_px` of `centre` (the mirror's disc; <= 0: whole image).
double image_entropy(const Image& img, const Eigen::Vector2d& centre = {0, 0}, double outer_radius_px = 0.0);

/// Mean grey value (0..255) of the disc of radius `radius_px` around `centre`: the robot's own body
/// in a catadioptric image, whose brightness follows the illumination and not the scene.
double centre_brightness(const Image& img, const Eigen::Vector2d& centre, double radius_px);

}  // namespace omniloc
