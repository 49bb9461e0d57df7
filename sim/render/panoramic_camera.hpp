#pragma once
// The simulated catadioptric camera: renders what a robot's omnidirectional camera sees, off-screen.
//
// Approach (measured against a cube-map + warp design and against per-pixel ray casting, see
// docs/camera.md): every vertex is projected through the mirror model on the CPU and GL only
// rasterises. The floor is an image-fixed polar mesh whose texture coordinates are the floor points
// its rays hit this frame; a fragment shader turns them into the markings from a distance field,
// anti-aliased over each pixel's extent across the line; mesh cells hidden behind the hall's walls
// are skipped. Other objects (robots, ball, goals, walls, landmarks, floor patches) are tessellated
// and projected per vertex with depth testing, faces turned away left out. "high" quality renders at
// 2x2 supersampling. Photometry (exposure, gain, saturation, shot and read noise) is applied on the
// CPU through a table by GL level and noise step.
//
// Frames: world (metres); robot (x forward, y left, z up, metres); image (u right, v down, pixels).
// The robot's forward axis points up in the image (v decreasing), robot-left points left.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/messages.hpp"
#include "core/rng.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/render/label_class.hpp"
#include "sim/render/mirror.hpp"
#include "sim/world_state.hpp"

namespace omniloc::sim {

struct PanoramicCameraImpl;

class PanoramicCamera {
 public:
  /// Changes whenever the rendered pixels change (photometry, noise, how the scene is drawn): part
  /// of the cache key of the colour tables and calibration maps learned from rendered images.
  static constexpr int kPhotometryVersion = 5;  // 5: field_robot's defocus and motion blur computed anew
  /// Throws ConfigError for a bad configuration, RuntimeFailure when the GL back-end fails.
  PanoramicCamera(const CameraConfig& config, const Field& field);
  ~PanoramicCamera();
  PanoramicCamera(const PanoramicCamera&) = delete;
  PanoramicCamera& operator=(const PanoramicCamera&) = delete;

  /// RGB8 panorama seen by robot `robot_id`. Vibration and pixel noise are drawn from `rng`.
  Image render(const WorldState& world, int robot_id, const CameraSettings& settings, Rng& rng);
  /// Class id per pixel (every channel), aligned with render() without vibration or noise.
  Image render_labels(const WorldState& world, int robot_id);

  /// Truth projection of a robot-frame 3-D point (metres) to the image, without vibration.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& robot_point) const;
  /// Truth: the robot-frame floor point seen at pixel (u, v) (pixel centres at +0.5), no vibration.
  std::optional<Eigen::Vector2d> floor_point(double u, double v) const;

  Eigen::Vector2d centre() const;  ///< mirror axis in the image, pixels
  double body_radius_px() const { return mirror_.body_radius(); }
  double rim_px() const { return mirror_.rim(); }
  const CameraConfig& config() const { return cfg_; }
  const MirrorProfile& mirror() const { return mirror_; }
  const std::string& backend() const;
  /// The device the camera renders on (back-end, EGL device, GL vendor and renderer).
  const GlDeviceInfo& device() const;
  /// Settings clamped into the camera's ranges; `clamped` says whether anything changed.
  CameraSettings clamp(const CameraSettings& s, bool* clamped = nullptr) const;
  /// Pixel value (before noise and saturation) of a surface of albedo a under illumination 1 and the
  /// given settings: value = kResponse * a * illumination * exposure_ms * gain.
  static double response(double albedo, double illumination, const CameraSettings& s);

 private:
  std::unique_ptr<PanoramicCameraImpl> impl_;
  CameraConfig cfg_;
  MirrorProfile mirror_;
};

}  // namespace omniloc::sim
