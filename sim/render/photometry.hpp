#pragma once
// From the renderer's 16-bit radiance to the camera's 8-bit pixels: the sensor's response to
// exposure and gain, shot and read noise from a table of standard normals, rounding and clipping;
// and, before that, what the optics do to the light over the exposure (motion blur by sub-frames and
// a rotation smear, defocus: image_blur.hpp). Kept apart from the drawing because it is plain CPU
// arithmetic on a buffer, and because its row loop is compiled with its own flags (CMakeLists.txt).
//
// Units: pixel values in DN (0-255), exposure in ms, seconds for the exposure interval, metres and
// radians for motion. Frames: image (u right, v down, pixels) for the output; the read-back buffer
// is render space in GL order (the image times the supersampling factor, rows bottom-up).
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/messages.hpp"
#include "core/rng.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/image_blur.hpp"
#include "sim/render/mirror.hpp"

namespace omniloc::sim {

// GL colours carry albedo * illumination / kRadianceScale, so illumination up to 4x normal fits.
inline constexpr float kRadianceScale = 4.0f;
// Camera response: value (DN) = kResponse * albedo * illumination * exposure_ms * gain. The sensor's
// sensitivity is set so that, under normal light, the image entropy along exposure = gain peaks at
// 18 / 18 as paper 002 reports for its camera (measured with `omniloc experiment entropy_maps`):
// the carpet's green channel then sits near 180 DN and the white lines clip, as on many robot cameras.
// (v1 put the lines at 200 DN at 18 / 18; its entropy peak lay at 26-30.)
inline constexpr double kResponse = 2.25 * 200.0 / (0.85 * 18.0 * 18.0);

class Photometry {
 public:
  /// `ss`: the supersampling factor of the read-back buffer.
  Photometry(const CameraConfig& cfg, const MirrorProfile& mirror, int ss);

  /// Fills the noise table from `rng` on the first call only (later calls draw nothing).
  void draw_noise_table(Rng& rng);
  /// Sub-frames an exposure of `exposure_s` seconds needs for a robot moving at `speed` m/s.
  int subframes(double speed, double exposure_s) const;

  /// The read-back buffer of a one-frame exposure (RGBA16, GL order).
  std::vector<std::uint16_t>& radiance() { return readback16_; }
  /// Motion blur by sub-frames: clear the sum, then per sub-frame read into subframe() and add it,
  /// then average into radiance().
  void clear_sum();
  std::vector<std::uint16_t>& subframe() { return subframe_; }
  void add_subframe();
  void average(int subframes);
  /// The depth buffer of radiance()'s render (read it when translation_blur() is to follow).
  std::vector<float>& depth() { return depth_; }
  /// Motion blur of a static scene from one render at mid-exposure (image_blur.hpp TranslationBlur):
  /// `velocity` the robot's in its own frame (m/s), `taus` the sub-frames' times after the render (s).
  void translation_blur(const Eigen::Vector2d& velocity, const std::vector<double>& taus);

  /// Rotation smear over `turn` radians (when motion blur is on), then defocus (when on).
  void apply_optics(double turn);
  /// The 8-bit image of radiance() under settings `st` (already clamped); `offset`: where in the
  /// noise table this frame starts.
  Image expose(const CameraSettings& st, std::uint64_t offset);

 private:
  CameraConfig cfg_;
  int ss_, W_, H_;
  Eigen::Vector2d centre_;  // mirror axis, image pixels
  double rim_;              // image pixels
  std::vector<std::uint16_t> readback16_;  // radiance, RGBA16
  std::vector<std::uint16_t> subframe_;    // one sub-frame of a motion-blurred exposure
  std::vector<std::uint32_t> accumulate_;  // the sum of the sub-frames
  std::unique_ptr<RadialDefocus> defocus_;  // null: sharp
  std::unique_ptr<RotationSmear> smear_;    // null: no motion blur
  std::unique_ptr<TranslationBlur> translation_;  // null: no motion blur
  std::vector<float> depth_;
  double finest_floor_m_per_px_ = 0.0;      // the smallest floor extent of an image pixel (at the body's edge)
  std::vector<std::uint8_t> noise_;         // standard normals in steps of kNoiseStep, drawn once from the first render's Rng
  std::vector<float> row_radiance_;         // one row's linear values
};

}  // namespace omniloc::sim
