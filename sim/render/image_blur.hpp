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
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "sim/render/mirror.hpp"

namespace omniloc::sim {

/// A view of the read-back buffer: width x height RGBA16, rows bottom-up.
struct Rgba16View {
  std::uint16_t* data = nullptr;
  int width = 0, height = 0;
};

/// Bilinear resampling of an RGBA16 image (CV_16UC4) at the coordinates of `map` (CV_32FC2,
/// pixel-index units, the border replicated), rounded to the nearest value: what cv::remap with
/// INTER_LINEAR does, in float weights instead of its 1/32-pixel table, 4 channels per SSE2 vector
/// (OpenCV's remap has no vector path for 16-bit data: 6 ms against ~2 ms for a 640 x 640 frame).
void remap_rgba16(const cv::Mat& src, const cv::Mat& map, cv::Mat& dst);

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
  cv::Mat to_polar_, from_polar_;  // remap tables (CV_32FC2), computed once per camera
  cv::Mat polar_, smeared_, back_;
  std::vector<std::uint32_t> sum_;
  std::vector<float> frac_row_;
};

/// Translation blur of the static scene from one render at mid-exposure (docs/camera.md "How the
/// effects are computed"; it replaced re-rendering the scene once per sub-frame when nothing but
/// the observer moves). Every pixel sees a surface point at a known distance (the depth buffer;
/// where nothing wrote depth, the floor the pixel's ray hits, or the far hall); while the robot
/// translates at v, that point moves in the image at a velocity u(p) that follows from the mirror's
/// profile: radially R'(e) sin(e) (u.v) / D and
/// across r (u x v) / (D cos e). The sub-frame at time tau after mid-exposure is the render resampled
/// at p - u(p) tau (bilinear), and the exposure is the mean of the sub-frames. The per-pixel
/// geometry (bearing, R'(e) sin e, r / cos e, the floor's distance) depends on the camera only and
/// is computed once. Samples are kept off the robot's own body and inside the rim (a floor pixel
/// next to the body samples the floor at the body's edge instead of the body). A pixel whose image
/// moves less than a pixel over the whole exposure keeps the mid-exposure render: bilinear samples
/// a fraction of a pixel apart would soften it by more than the motion does (its box of length
/// L < 1 px adds a variance of L^2 / 12 px^2; linear interpolation at an offset d adds d (1 - d)).
class TranslationBlur {
 public:
  /// `ss`: supersampling factor; `centre`: mirror axis in image pixels (render space, y down).
  TranslationBlur(int width, int height, int ss, const Eigen::Vector2d& centre, const MirrorProfile& mirror, double mount_height);
  /// `depth`: the render's depth buffer (GL order, metres / 1000, 1 where nothing wrote depth);
  /// `velocity`: the robot's, robot frame, m/s; `taus`: sub-frame times relative to the render,
  /// seconds (positive: later). Replaces `img` by the mean of the sub-frames.
  void apply(const Rgba16View& img, const std::vector<float>& depth, const Eigen::Vector2d& velocity, const std::vector<double>& taus);

 private:
  struct Moved {
    std::uint32_t index;       // pixel
    std::uint16_t value[4];    // its mean over the sub-frames
  };
  int width_, height_;
  float cx_, cy_, r_min_, r_max_;                   // mirror axis in buffer-index coordinates; sample radii kept within
  std::vector<float> m_;                            // per pixel: image velocity per unit robot velocity x distance (2 x 2, row-major)
  std::vector<float> inv_floor_;                    // per pixel: 1 / distance to the floor along the ray (0: none)
  std::vector<std::pair<int, int>> span_;           // per row: the columns of the ring
  std::vector<std::vector<Moved>> moved_;           // per row: the pixels that move, with their means
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
  int y0_ = 0, y1_ = 0;          // the rows that hold the rim's disc (the rest is left as drawn)
  std::vector<float> c1_, c2_;    // per pixel: out = I + c1 (half - I) + c2 (full - half); 0, 0 outside the rim
  std::vector<std::pair<int, int>> span_;  // per row: the columns inside the rim
  std::vector<cv::Rect> full_rects_;       // where the full level is needed (c2 > 0)
  cv::Mat src_f_, half_, full_;
};

}  // namespace omniloc::sim
