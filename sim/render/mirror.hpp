#pragma once
// Rotationally symmetric mirror profiles: the map between image radius (pixels from the mirror
// axis) and the elevation of the viewing ray (radians, negative below the horizon, seen from the
// mirror's effective viewpoint at the camera mount height). This is the simulator's truth; the
// localization side never sees it (it only has the calibration map built from images).
#include <string>
#include <vector>

namespace omniloc::sim {

class MirrorProfile {
 public:
  /// "nubot_composite" (default), "hyperbolic" or "nubot_tan" (NuBot's measured d = a tan(b r)); scaled so that the outer rim sits at `rim_px`.
  /// `mount_height`: viewpoint height above the floor, metres. Throws ConfigError (path "/camera/mirror").
  static MirrorProfile preset(const std::string& name, double rim_px, double mount_height);
  static std::vector<std::string> presets() { return {"nubot_composite", "hyperbolic", "nubot_tan"}; }

  /// Image radius (px) of a ray of elevation e (rad). Extrapolated beyond the rim (outside the image).
  double radius(double elevation) const;
  /// Elevation (rad) seen at image radius r (px); valid for body_radius() <= r <= rim().
  double elevation(double radius_px) const;
  double body_radius() const { return body_px_; }  ///< inside: the robot's own body
  double rim() const { return rim_px_; }           ///< outside: the mirror's edge (black)
  const std::string& name() const { return name_; }
  /// Elevation of the horizon-most ray that still hits the floor at `distance` metres.
  double elevation_of_floor(double distance) const;

 private:
  std::string name_;
  double h_ = 0.75, body_px_ = 0, rim_px_ = 0;
  std::vector<double> e_, r_;  // dense monotone table, e increasing
};

}  // namespace omniloc::sim
