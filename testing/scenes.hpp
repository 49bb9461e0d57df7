#pragma once
// Scenes shared by the tests (tests/) and the benchmarks (bench/, including the instruction-count
// workloads of bench/icount.cpp): one definition of each synthetic input, so a test and a benchmark
// that name the same scene get the same numbers. World frame, metres, radians. Only tests/ and bench/
// use this folder (the layering test, scripts/check_layers.py, keeps it out of the libraries).
#include <cstddef>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/messages.hpp"
#include "core/pose2.hpp"
#include "core/rng.hpp"
#include "localization/landmarks/landmark_fix.hpp"
#include "sim/render/camera_config.hpp"
#include "sim/world_state.hpp"

namespace omniloc {
class FieldMap;
}

namespace omniloc::scenes {

// ---- Rendered scenes ----

/// The default camera without vibration or pixel noise: known answers need a still, clean image.
sim::CameraConfig quiet_camera();

/// Robot 0 alone at `pose` (world frame), no ball.
sim::WorldState one_robot(const Pose2& pose);

// ---- Line points: what a perfect line detector would report ----

struct LinePointOptions {
  enum class Area { kDisc, kSquare };
  double range = 6.0;       ///< metres: samples within this distance of the robot
  Area area = Area::kDisc;  ///< the disc of radius `range`, or the square of half-side `range`
  double noise = 0.0;       ///< metres, standard deviation per coordinate (0: exact points, no draws)
  /// A distance map of the field: rejects most samples before the exact (slower) test. It is exact
  /// to half a cell, so it changes no point, only the time taken.
  const FieldMap* prefilter = nullptr;
  long max_draws = 3000000;  ///< candidates drawn at most; fewer than `n` points come back after that
};

/// The benchmarks' scene (bench/localization_bench.cpp and bench/icount.cpp measure the same inputs).
inline constexpr LinePointOptions kBenchmarkLinePoints{.area = LinePointOptions::Area::kSquare, .noise = 0.03};

/// `n` points on the field's markings (within 4 mm of a line's centre) seen from `pose`, in the
/// robot frame, drawn uniformly over the area around the robot.
std::vector<Eigen::Vector2d> line_points(const Field& f, const Pose2& pose, int n, Rng& rng, const LinePointOptions& o = {});

// ---- Landmark bearings ----

/// Centre and radius of the circle through three points (not collinear).
void circumcircle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, Eigen::Vector2d& centre, double& r);

/// Distance from p to the circle through a, b and c.
double distance_to_circle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& p);

/// Distance from p to the whole (infinite) line through a and b.
double distance_to_line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p);

inline constexpr std::size_t kLandmarkConfigs = 1024;

/// kLandmarkConfigs configurations of `n` landmarks (n >= 3) with their bearings, Gaussian noise
/// `sigma` (radians), from the fixed seed 2024 + n; made once per (n, sigma) and kept (not
/// thread-safe). Landmarks in an 18 m x 12 m field, at least 2 m apart, the first three a triangle
/// with every angle over 15 degrees; the robot pose uniform in 20 m x 14 m, at least 0.5 m from every
/// landmark, from the circle through the first three and from the lines through landmarks 0-1 and
/// 1-2 (so every closed-form solver has a fix).
const std::vector<std::vector<landmarks::BearingObs>>& landmark_configs(int n, double sigma);

// ---- Images ----

/// Mean absolute difference of two images over the pixels whose centres lie from r_min to r_max
/// pixels of `c` (all three channels), DN.
double mean_abs_diff(const Image& a, const Image& b, const Eigen::Vector2d& c, double r_min, double r_max);

/// The pixel-wise mean of `n` images render(0) .. render(n - 1), rounded to DN: the exposure integral
/// the camera tests compare motion blur with (render(k) draws the scene at sub-instant k).
Image mean_image(int n, const std::function<Image(int k)>& render);

}  // namespace omniloc::scenes
