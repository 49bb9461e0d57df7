#pragma once
// Localizer "landmarks": a pose from the bearings of coloured blobs to the field's known coloured
// objects, one frame at a time (papers 004 and 003), with optional odometry prediction between fixes.
//
// Known objects (from the field, the map every team has):
//  - each landmark (cube or post) whose colour has a colour class (yellow, blue, red): its centre,
//    matched by Blob::Kind::kRegion blobs of that colour;
//  - each coloured goal: its left and right silhouette edges, matched by kLeftEdge / kRightEdge blobs
//    of the goal's colour. A goal's footprint (posts and net) is a rectangle; the edge the robot sees
//    is the rectangle corner at the extreme bearing from where the robot stands (the front outer
//    corner when it is in front of the goal, a back corner of the net when it stands off to the
//    side). The corners are chosen from the predicted pose (or the field centre), then again from
//    each fix until they no longer change (at most 3 solves).
//
// Association: blobs are grouped by (colour, kind); within a group every one-to-one assignment of
// blobs to same-coloured objects is tried (two red cubes: both ways), the larger blobs first when a
// group has more blobs than objects. Each assignment is solved (>= 4 bearings: least_squares_bearings;
// exactly 3: total_like) and scored by
//   cost = sum bearing_residual^2 / sigma_b^2
//        + sum over blobs with a distance ((|L - P| - r_L - d) / (sigma_d * max(d, 0.5 m)))^2
//        + |P - P_pred|^2 / sigma_p^2 + dtheta^2 / sigma_theta^2     (while a prediction is recent)
// with r_L the object's half size (the distance is to its nearest face) and the lowest cost wins.
// Fixes off the floor (plus floor_slack) are discarded; a winner with a bearing RMS above
// max_bearing_rms_deg is refused; two different poses (> 0.5 m or > 10 degrees apart) within
// ambiguity_margin of the best cost make the frame ambiguous.
//
// A frame without a fix is reported honestly: valid = false, mode "no_fix" and the reason code in
// extra["no_fix_reason"] (see NoFixReason), the running count in extra["no_fix_total"]. With
// odometry_prediction on, such a frame instead reports the last pose moved by odometry (mode
// "odometry", valid) for up to max_prediction_time seconds after the last fix. The compass / MTi
// heading is not used (papers 004 and 003 have none); the camera's latency is not compensated.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "localization/landmarks/landmark_fix.hpp"
#include "localization/localizer.hpp"

namespace omniloc {

struct LandmarkLocalizerParams {
  int min_landmarks = 3;               ///< fewer matched bearings: no fix (3 is the minimum for any solver)
  double bearing_sigma_deg = 1.0;      ///< expected bearing noise: assignment cost and covariance
  double max_bearing_rms_deg = 3.0;    ///< a fix whose RMS bearing residual is larger is refused (>= 4 bearings)
  double distance_sigma = 0.15;        ///< relative error of blob distances in the cost; 0: distances unused
  double prediction_sigma = 0.5;       ///< m, predicted position's weight in the cost; 0: prediction unused
  double prediction_sigma_theta_deg = 15.0;  ///< degrees, predicted heading's weight
  double ambiguity_margin = 1.0;       ///< cost units (chi-square): closer rivals make the frame ambiguous
  double floor_slack = 0.5;            ///< m a fix may lie outside the floor (walls) before it is discarded
  bool skip_occluded = true;           ///< blobs whose edge may be cut by an occluder are not used
  bool odometry_prediction = false;    ///< report the odometry-predicted pose on frames without a fix
  double max_prediction_time = 2.0;    ///< s after the last fix that prediction is used (cost and output)
  int max_assignments = 256;           ///< assignments tried per frame at most
  static LandmarkLocalizerParams from_json(JsonReader& r);
  static const ParamList<LandmarkLocalizerParams>& params();
};

/// Why a frame has no fix (extra["no_fix_reason"]; 0 = fix).
enum class NoFixReason : int {
  kNone = 0,
  kCameraNotOk = 1,     ///< image unusable (covered, dark)
  kTooFewLandmarks = 2, ///< fewer than min_landmarks blobs matched a known object
  kSolverRefused = 3,   ///< every assignment's geometry was refused (singular, collinear, off the floor)
  kInconsistent = 4,    ///< the best fix's bearing residual is above max_bearing_rms_deg
  kAmbiguous = 5,       ///< two assignments fit about equally well at different poses
};
const char* no_fix_reason_name(NoFixReason r);

/// A known object a blob can be matched to.
struct KnownObject {
  std::string id;                    ///< landmark id, or "<colour>_goal_left" / "_right"
  ColourClass colour = kUnknown;
  Blob::Kind kind = Blob::Kind::kRegion;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< landmark centre (world, m); goals: see corners
  double half_size = 0.0;            ///< m from the centre to the nearest face (distance check)
  bool is_goal_edge = false;
  Eigen::Vector2d footprint_min = Eigen::Vector2d::Zero(), footprint_max = Eigen::Vector2d::Zero();  ///< goal rectangle
  /// The point whose bearing the blob measures when seen from `viewpoint` (world, m): the centre for
  /// landmarks, the extreme silhouette corner for goal edges.
  Eigen::Vector2d seen_from(const Eigen::Vector2d& viewpoint) const;
};

/// The objects of `field` that blobs can be matched to (colours without a colour class are skipped).
std::vector<KnownObject> known_objects(const Field& field);

/// Everything one frame's solve did (tests and diagnostics).
struct LandmarkFrame {
  NoFixReason reason = NoFixReason::kNone;
  std::string detail;            ///< solver's reason or a description, empty on a fix
  landmarks::Fix fix;
  int matched = 0;               ///< bearings used by the chosen assignment
  int assignments = 0;           ///< assignments tried
  double bearing_rms = 0.0;      ///< rad
  double cost = 0.0;
  std::vector<std::string> ids;  ///< object ids of the chosen assignment, in blob order
};

class LandmarkLocalizer : public Localizer {
 public:
  LandmarkLocalizer(const Field& field, const LandmarkLocalizerParams& p);
  std::string type() const override { return "landmarks"; }
  void reset(const std::optional<Pose2>& start) override;
  Estimate update(const Observations& obs, const Odometry& odometry, std::optional<double> heading) override;

  /// One frame's association and solve, from the blobs alone (plus an optional predicted pose).
  LandmarkFrame solve(const std::vector<Blob>& blobs, const std::optional<Pose2>& predicted) const;
  const LandmarkFrame& last_frame() const { return last_; }
  const std::vector<KnownObject>& objects() const { return objects_; }

 private:
  Field field_;
  LandmarkLocalizerParams p_;
  std::vector<KnownObject> objects_;
  Pose2 pose_;               // last reported pose (fix or prediction)
  bool have_pose_ = false;
  double since_fix_ = 1e9;   // s since the last fix
  double last_t_ = 0.0;
  bool have_t_ = false;
  long long no_fix_total_ = 0;
  LandmarkFrame last_;
};

}  // namespace omniloc
