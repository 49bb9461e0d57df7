#pragma once
// What a real catadioptric camera does to the light before the sensor digitises it: the smear of
// the robot's rotation over the exposure and the lens's defocus, which grows towards the mirror's
// rim. Both work on the renderer's linear RGBA16 buffer (GL order: rows bottom-up), before noise,
// gain and clipping, as in the camera. Each keeps its maps and buffers from frame to frame (fresh
// multi-megabyte buffers per frame cost more in page faults than the filtering).
//
// Frames and units: render space (x right, y down, pixels of the supersampled buffer); `centre` is
// the mirror axis there (pixel centres at +0.5); radii in the same pixels.
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace omniloc::sim {

/// A view of the read-back buffer: width x height RGBA16, rows bottom-up.
struct Rgba16View {
  std::uint16_t* data = nullptr;
  int width = 0, height = 0;
};

/// The image's mean over the arc swept while it turns about the mirror axis: exact for a rotation
/// about that axis. The image is resampled to polar coordinates (one angle sample per pixel of the
/// rim's circumference), averaged along angle over the swept arc with fractional end samples, and
/// resampled back: two bilinear resamplings, about 0.3 px of extra softening, so arcs shorter than a
/// twentieth of a pixel at the rim are left alone.
class RotationSmear {
 public:
  RotationSmear(int width, int height, const Eigen::Vector2d& centre, double rim);
  /// `angle`: radians the image turned over the exposure, positive anticlockwise in render space
  /// (x right, y down), i.e. clockwise as seen on screen.
  void apply(const Rgba16View& img, double angle);

 private:
  int width_, height_, nr_, na_;
  double rim_;
  cv::Point2f centre_;  // in the stored buffer's pixel-index coordinates
  cv::Mat to_polar_a_, to_polar_b_, from_polar_a_, from_polar_b_;  // remap tables (fixed point)
  cv::Mat polar_, smeared_, back_;
  std::vector<double> sum_;
};

/// Defocus: a Gaussian point-spread function whose standard deviation (pixels of this buffer) is
/// sigma(r) at radius r from `centre` (sigma_by_radius[i] at r = i, linear in between). The image is
/// blurred at three levels (0, sigma_max / 2, sigma_max) and each pixel blends the two levels
/// around its own sigma.
class RadialDefocus {
 public:
  RadialDefocus(int width, int height, const Eigen::Vector2d& centre, double rim, const std::vector<double>& sigma_by_radius);
  bool active() const { return sigma_max_ > 0.05; }
  void apply(const Rgba16View& img);

 private:
  int width_, height_;
  double sigma_max_ = 0.0;
  std::vector<std::uint8_t> level_;   // per pixel: the lower level (0 or 1), 255 outside the rim
  std::vector<std::uint16_t> share_;  // per pixel: weight of the upper level, 1/65536 units
  cv::Mat half_, full_;
};

}  // namespace omniloc::sim
