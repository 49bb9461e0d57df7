#include "sim/render/camera_config.hpp"

#include "core/angles.hpp"
#include "sim/render/egl_device.hpp"
#include "sim/render/gl_context.hpp"
#include "sim/render/mirror.hpp"

namespace omniloc::sim {

CameraConfig CameraConfig::from_json(const Json& j, const std::string& path, Json* effective) {
  JsonReader r(j, path, effective);
  r.allow("comment");
  CameraConfig c;
  c.width = static_cast<int>(r.integer("width", 640, 1, 4096));
  c.height = static_cast<int>(r.integer("height", 640, 1, 4096));
  if (c.width < 64 || c.height < 64)
    throw ConfigError(r.child_path(c.width < 64 ? "width" : "height"), std::to_string(std::min(c.width, c.height)),
                      "an image size of at least 64 pixels");
  c.mount_height = r.number("mount_height", 0.75, 0.2, 2.0);
  c.mirror = r.string("mirror", std::string("nubot_composite"), MirrorProfile::presets());
  c.rim_fraction = r.number("rim_fraction", 0.49, 0.2, 0.5);
  const auto off = r.numbers("centre_offset_px", std::vector<double>{0.0, 0.0}, 2);
  c.centre_offset_px = {off[0], off[1]};
  // Settings that validate but cannot be calibrated were found at run time ("only 0 of 36
  // directions showed all 15 patch edges"). Measured with omniloc calibrate on the default mirror:
  // a mirror radius of 188 px calibrates all 36 directions, 172 px 21, 157 px fails; an offset that
  // pushes the mirror's disc 5 px past the image border costs half the directions, 16 px more fail.
  // So the mirror's radius must be at least 180 px and its disc may leave the picture by 10 px at most.
  const double side = std::min(c.width, c.height), rim_px = c.rim_px();
  if (rim_px < 180.0)
    // Blame rim_fraction when a larger one would do on this image, else the image size.
    throw ConfigError(r.child_path(0.5 * side >= 180.0 ? "rim_fraction" : c.width <= c.height ? "width" : "height"),
                      0.5 * side >= 180.0 ? std::to_string(c.rim_fraction) : std::to_string(std::min(c.width, c.height)),
                      "an image with a mirror radius (rim_fraction x the smaller side, here " + std::to_string(rim_px) +
                          " px) of at least 180 px; smaller mirror images cannot be calibrated");
  if (c.centre_offset_px.norm() + rim_px > 0.5 * side + 10.0)
    throw ConfigError(r.child_path("centre_offset_px"), json_brief(j["centre_offset_px"]),
                      "an offset of at most " + std::to_string(0.5 * side + 10.0 - rim_px) +
                          " px (the mirror's disc must stay inside the image, 10 px of it may be cut); otherwise it cannot be calibrated");
  c.mirror_tilt = deg2rad(r.number("mirror_tilt_deg", 0.0, -5.0, 5.0));
  c.vibration_std = deg2rad(r.number("vibration_deg", 0.3, 0.0, 5.0));
  c.latency = 1e-3 * r.number("latency_ms", 0.0, 0.0, 500.0);
  c.tilt_per_accel = deg2rad(r.number("tilt_deg_per_mps2", 0.0, 0.0, 5.0));
  c.optical_blur_px = r.number("optical_blur_px", 0.0, 0.0, 20.0);
  c.focus_radius_fraction = r.number("focus_radius_fraction", 0.5, 0.0, 0.95);
  c.motion_blur = r.boolean("motion_blur", false);
  c.read_noise = r.number("read_noise", 1.5, 0.0, 50.0);
  c.shot_noise = r.number("shot_noise", 0.35, 0.0, 10.0);
  c.backend = r.string("backend", std::string("osmesa"), gl_backends());
  // A sweep renders on a GPU without editing its scenarios: the variable wins over the file.
  c.backend = effective_gl_backend(c.backend);
  c.quality = r.string("quality", std::string("default"), {"low", "default", "high"});
  c.exposure_min = r.positive("exposure_min", 1.0, 1000.0);
  c.exposure_max = r.positive("exposure_max", 60.0, 1000.0);
  c.gain_min = r.positive("gain_min", 1.0, 1000.0);
  c.gain_max = r.positive("gain_max", 60.0, 1000.0);
  c.initial.exposure_ms = r.positive("exposure", 18.0, 1000.0);
  c.initial.gain = r.positive("gain", 18.0, 1000.0);
  if (c.exposure_min >= c.exposure_max) throw ConfigError(r.child_path("exposure_max"), std::to_string(c.exposure_max), "exposure_max > exposure_min");
  if (c.gain_min >= c.gain_max) throw ConfigError(r.child_path("gain_max"), std::to_string(c.gain_max), "gain_max > gain_min");
  if (c.initial.exposure_ms < c.exposure_min || c.initial.exposure_ms > c.exposure_max)
    throw ConfigError(r.child_path("exposure"), std::to_string(c.initial.exposure_ms), "an exposure within [exposure_min, exposure_max]");
  if (c.initial.gain < c.gain_min || c.initial.gain > c.gain_max)
    throw ConfigError(r.child_path("gain"), std::to_string(c.initial.gain), "a gain within [gain_min, gain_max]");
  r.finish();
  if (effective) (*effective)["backend"] = c.backend;
  return c;
}

Json CameraConfig::to_json() const {
  return Json{{"width", width}, {"height", height}, {"mount_height", mount_height}, {"mirror", mirror}, {"rim_fraction", rim_fraction},
              {"centre_offset_px", {centre_offset_px.x(), centre_offset_px.y()}}, {"mirror_tilt_deg", rad2deg(mirror_tilt)},
              {"vibration_deg", rad2deg(vibration_std)}, {"latency_ms", 1e3 * latency},
              {"tilt_deg_per_mps2", rad2deg(tilt_per_accel)}, {"optical_blur_px", optical_blur_px},
              {"focus_radius_fraction", focus_radius_fraction}, {"motion_blur", motion_blur}, {"read_noise", read_noise}, {"shot_noise", shot_noise}, {"backend", backend},
              {"quality", quality}, {"exposure", initial.exposure_ms}, {"gain", initial.gain}, {"exposure_min", exposure_min},
              {"exposure_max", exposure_max}, {"gain_min", gain_min}, {"gain_max", gain_max}};
}

}  // namespace omniloc::sim
