#pragma once
// Rendered-image mode of the paper-001 simulation (issue 9): instead of "true ball + Gaussian noise",
// every robot renders its own panorama with the simulated omnidirectional camera
// (sim/render/panoramic_camera.hpp), finds the ball (the orange colour class) with the robot-side
// BlobDetector through the calibration map and colour table of harness/vision_setup.hpp, and turns
// the blob's bearing and distance, with its own self-localised pose, into the line L_i of the Hough
// fix (localization/cooperative/hough_ball.hpp). The five robots are obstacles in each other's
// images, so occlusions are real. docs/cooperative.md, "Rendered mode", has the results.
//
// Frames and units: the experiment's "paper frame" (metres, origin at a field corner, x along the
// long side, as in cooperative_001.hpp); the rendered field uses the project's field frame (metres,
// origin at the field centre), i.e. paper point p is field point p - (length / 2, width / 2).
// Robot frame: x forward, y left, metres; bearings in radians anticlockwise from forward.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/messages.hpp"
#include "localization/vision/blobs.hpp"
#include "sim/render/camera_config.hpp"

namespace omniloc::harness {
class RunDirectory;
}

namespace omniloc::experiments {

struct Cooperative001Config;

/// Where each robot's own pose (the start of its line L_i) comes from.
enum class CoopPoseSource {
  /// Self-localisation: the "matching" localizer on the robot's own rendered images for
  /// `selfloc_frames` frames, started from the true pose perturbed by start_offset / start_heading_offset.
  Matching,
  /// Ground truth + N(0, pose_sigma^2 I) on the position (fallback when self-localisation is not wanted).
  NoisyTruth,
};

const char* to_string(CoopPoseSource s);

/// "rendered" object of scenarios/experiments/cooperative_001.json.
struct CoopRenderedConfig {
  Field field;                    ///< the rendered field, field frame; same length / width as /field
  sim::CameraConfig camera;       ///< every robot's camera (default: the project's default camera)
  std::vector<double> headings;   ///< rad, world heading of each robot; empty: each faces the path's middle
  int trials = 30;                ///< Monte Carlo runs of the whole path with new image noise
  int quick_trials = 1;
  int min_area_px = 6;            ///< smallest orange region accepted as the ball (pixels)
  double ball_radius = 0.11;      ///< m, the ball every robot knows (MSL size-5 ball, sim default)
  double robot_radius = 0.26;     ///< m, the robots' footprint (sim default), also for the occlusion count
  double robot_height = 0.8;      ///< m
  CoopPoseSource pose_source = CoopPoseSource::Matching;
  Json localizer = Json{{"type", "matching"}};  ///< localizer description (localizer_registry) for Matching
  int selfloc_frames = 15;        ///< frames each robot self-localises on before the ball rolls
  double start_offset = 0.3;      ///< m, distance of the localizer's start from the true position
  double start_heading_offset = 0.17453292519943295;  ///< rad (10 degrees), start heading error
  double pose_sigma = 0.05;       ///< m, NoisyTruth only
  /// Tracker runs on the rendered fixes are cheap (no rendering): every trial feeds its fix sequence
  /// to each tracker this many times with different filter seeds.
  int tracking_repeats = 20;
};

/// Strict parsing of the "rendered" object (`r` at /rendered); field size checked against `c`.
CoopRenderedConfig parse_coop_rendered(JsonReader& r, const Cooperative001Config& c);

/// One robot's ball measurement from one panorama, robot frame.
struct RenderedBallSighting {
  bool seen = false;             ///< an orange region of at least min_area_px was found
  bool has_distance = false;     ///< its nearest ground contact lies inside the calibrated range
  double bearing = 0.0;          ///< rad, middle of the region's angular extent
  double contact_distance = 0.0; ///< m, floor distance of the region pixel nearest the image centre
  double distance = 0.0;         ///< m, ball centre's floor distance after the radius correction
  int area_px = 0;
  int regions = 0;               ///< orange regions found (the largest is used)
  Eigen::Vector2d position() const;  ///< robot frame, metres: distance * (cos bearing, sin bearing)
};

/// Horizontal distance (m) from the mirror axis to the ball centre, given the floor distance d (m)
/// where the steepest ray that still touches the ball (the region's pixel nearest the image centre)
/// meets the floor, the camera's viewpoint height h (m) and the ball radius r (m). That ray is
/// tangent to the ball on its near side, so it meets the floor short of the ball's contact point;
/// the ball centre lies at perpendicular distance r from it: D = d + r (sqrt(h^2 + d^2) - d) / h.
double ball_centre_distance(double contact_distance, double mount_height, double ball_radius);

/// The largest orange region of `blobs` (kBallOrange, Kind::kRegion) as a sighting.
RenderedBallSighting ball_sighting_from_blobs(const std::vector<Blob>& blobs, int min_area_px, double mount_height, double ball_radius);

/// Runs the rendered mode (c.rendered must be set) with `trials` path runs, appends its markdown
/// section to `md`, writes robots_vs_error_rendered.{csv,png} into `dir` and returns every number
/// as JSON (key "rendered" of cooperative_001.json). `progress`: optional one-line status stream.
Json run_cooperative_rendered(const Cooperative001Config& c, int trials, std::uint64_t seed, std::ostream& md, harness::RunDirectory& dir,
                              std::ostream* progress = nullptr);

}  // namespace omniloc::experiments
