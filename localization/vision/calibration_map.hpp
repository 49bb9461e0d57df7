#pragma once
// The model-free image -> robot-frame floor map of paper 002 (after Voigtlaender et al.): built
// from calibration images by `omniloc calibrate`, saved to a file, loaded by the pipeline. The
// localization side knows the camera only through this map, never through the simulator's mirror.
//
// Frames: image pixels (u right, v down, pixel centres at integer + 0.5); robot frame (metres,
// x forward, y left) on the floor. Calibration directions are robot-frame bearings; the image angle
// of a bearing b is atan2(-sin b, -cos b) (forward up, left left), the camera mounting convention.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/messages.hpp"

namespace omniloc {

class CalibrationMap {
 public:
  CalibrationMap() = default;

  int image_width() const { return width_; }
  int image_height() const { return height_; }
  Eigen::Vector2d centre() const { return centre_; }  ///< mirror axis in the image, pixels
  double min_radius() const { return min_radius_; }   ///< first calibrated radius (inside: robot body), pixels
  double max_radius() const { return max_radius_; }   ///< last calibrated radius, pixels
  /// Floor distance (metres) at image radius r along robot bearing b; nullopt outside the map.
  std::optional<double> ground_distance(double radius_px, double bearing) const;
  /// Robot-frame floor point seen at pixel (u, v); nullopt outside the map. Uses the dense table.
  std::optional<Eigen::Vector2d> to_robot(double u, double v) const;
  /// Image radius (pixels) at which a floor point at `distance` metres and `bearing` appears.
  std::optional<double> radius_for_distance(double distance, double bearing) const;
  /// The tables set_tables() was given: per direction (bearing 2 pi i / N) the image radii (pixels)
  /// and the floor distances (metres) of the calibration edges.
  const std::vector<std::vector<double>>& radii_px() const { return radii_; }
  const std::vector<std::vector<double>>& distances_m() const { return distances_; }

  /// Tables: for each of the directions (robot bearings evenly spaced from 0, anticlockwise), the
  /// increasing image radii of the calibration edges and their floor distances (metres). Radial:
  /// 4-point Lagrange interpolation in each direction; rotary: 4-point Lagrange across directions.
  void set_tables(int width, int height, Eigen::Vector2d centre, std::vector<std::vector<double>> radii_px,
                  std::vector<std::vector<double>> distances_m);
  /// Fingerprint of the camera/scene it was made for (checked on load when given).
  std::string tag;
  /// Radius (px) of the mirror rim the centre was estimated from; 0 when the centre was given
  /// (version-1 files, which took the image centre as the mirror axis).
  double rim_radius = 0.0;

  /// File format version 2 (version 1 plus "centre_source" and "rim_radius_px"); load() reads 1 and 2.
  void save(const std::string& path) const;
  /// Throws ConfigError naming the file on a missing or malformed file, or (when `expected_tag` is
  /// not empty) a map made for another camera, or of another image size.
  static CalibrationMap load(const std::string& path, const std::string& expected_tag = "", int width = 0, int height = 0);

 private:
  double radial(std::size_t dir, double r) const;
  void build_lut();
  int width_ = 0, height_ = 0;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  double min_radius_ = 0.0, max_radius_ = 0.0;
  std::vector<std::vector<double>> radii_, distances_;
  std::vector<float> lut_;  // x, y per pixel; NaN outside
};

/// One calibration image: the patch lies along robot bearing `bearing` (radians).
struct CalibrationView {
  Image image;
  double bearing = 0.0;
};

/// The mirror's rim in the image: a circle fitted to the boundary between the lit mirror image and
/// the black outside it. Its centre is the mirror axis.
struct MirrorRim {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< pixels
  double radius = 0.0;                               ///< pixels; 0 when not estimated
  double rms_px = 0.0;                               ///< rms geometric residual of the inliers
  int edge_points = 0;                               ///< rim points the circle was fitted to
  int rejected = 0;                                  ///< directions with no rim in the image (clipped) or outliers
};

/// Estimates the mirror rim from images of one camera (any scenes; the calibration views): the
/// pixel-wise maximum of their grey images is lit everywhere inside the mirror, whatever the scene
/// did, and black outside. The rim is found along `directions` radial profiles, to sub-pixel, and a
/// circle is fitted to it (algebraic fit, then geometric Gauss-Newton with iterated outlier
/// rejection; two passes, the second profiling from the first pass's centre). Directions in which
/// the rim leaves the image are skipped. Throws RuntimeFailure when fewer than 32 rim points remain.
MirrorRim estimate_mirror_rim(const std::vector<CalibrationView>& views, int directions = 720);

/// Least-squares circle through points: Kasa's algebraic fit, refined geometrically (minimising the
/// sum of squared distances to the circle), dropping points beyond max(0.5 px, 3.5 robust sigmas)
/// until none is dropped. `inlier` (optional) gets the flags. Needs >= 3 points not on one line.
MirrorRim fit_circle(const std::vector<Eigen::Vector2d>& points, std::vector<bool>* inlier = nullptr);

struct CalibrationResult {
  CalibrationMap map;
  int directions_used = 0;
  int directions_rejected = 0;
  MirrorRim rim;  ///< the estimated rim (radius 0 when the centre was given)
};

/// Finds the patch edges (cv::Canny on the grey image, refined to the grey-profile gradient peak
/// along the ray) in each view and builds the map. `edge_distances`: the patch's known edge
/// distances (core/calibration_patch.hpp); `centre`: the mirror axis as given (e.g. the image
/// centre: a decentred mirror then becomes calibration error); `body_radius`: pixels to skip
/// around the centre. Rays are searched to the image's inscribed radius. Throws RuntimeFailure when
/// fewer than 8 directions give all edges.
CalibrationResult calibrate_from_images(const std::vector<CalibrationView>& views, const std::vector<double>& edge_distances,
                                        const Eigen::Vector2d& centre, double body_radius);
/// As above with the mirror axis estimated from the views' rim (estimate_mirror_rim): the map's
/// centre is the rim's, and rays are searched up to just inside the rim. The default.
CalibrationResult calibrate_from_images(const std::vector<CalibrationView>& views, const std::vector<double>& edge_distances, double body_radius);

}  // namespace omniloc
