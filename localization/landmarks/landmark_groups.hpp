#pragma once
// Paper 003 (Zhuang & Cao, "Global Localization of Explorer Based on Visible Landmarks", J. Shanghai
// Jiao Tong Univ. 43(6), 2009): landmark groups, their matching between consecutive frames, one fix
// per group by circle intersection, and the voting that turns the group fixes into one position.
//
//  - Group (sec. 1, fig. 1): three landmarks of three different colours seen in one frame. Its feature
//    vector P = (|d12|, |d13|, alpha): d12, d13 the vectors from landmark 1 to landmarks 2 and 3,
//    alpha the signed angle from d12 to d13 (anticlockwise positive). P does not change when the
//    robot moves or turns (the paper's "scale and rotation invariance": the landmarks are static).
//    Which landmark is 1, 2, 3: the paper's figure fixes it by hand; we order a group's members by
//    increasing colour id (our choice), so the numbering is the same in every frame.
//  - Matching (sec. 1, fig. 2): a group of the current frame matches a group of the previous frame
//    when the feature difference is below a threshold. The paper gives neither the thresholds nor
//    how to combine the three differences: we require the same three colours and each difference
//    within its own threshold, and resolve competition one-to-one, smallest normalised difference
//    first.
//  - Global landmark coordinates (sec. 1): the landmarks' positions are not known in advance; the
//    global frame is the robot's start pose, and a group's landmarks get global coordinates from
//    their position relative to the robot and the current robot position. We set them when a group
//    is first seen (not matched to the previous frame) and carry them along matches.
//  - Fix (sec. 2.1): three-point localisation by circle intersection (circle_intersection_003).
//  - Voting (sec. 2.2, the pseudo-code): each fix gets one vote from itself and one per other fix
//    within 0.5 m and 10 degrees; the average of the best-voted fix and its neighbours is accepted
//    if it lies in the plausible region (the circle whose diameter joins the planned path's start
//    and goal, "enlarged as needed") or after more than 3 deadlocks (consecutive frames without an
//    accepted position); otherwise the last position is kept. See FixVoter for the exact order.
//
// Units: metres and radians throughout; positions in the global frame, sightings in the robot frame
// (x forward, bearings anticlockwise from the robot's x axis, as in landmark_fix.hpp).
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "core/angles.hpp"
#include "core/pose2.hpp"
#include "localization/landmarks/landmark_fix.hpp"

namespace omniloc::landmarks {

/// One landmark (a colour blob) seen in one frame.
struct LandmarkSighting {
  int colour = 0;         ///< colour id; a group needs three different ids
  double distance = 0.0;  ///< metres, robot centre to landmark (from the camera's distance calibration)
  double bearing = 0.0;   ///< radians, robot frame, anticlockwise from the robot's x axis
  /// Position in the robot frame, metres.
  Eigen::Vector2d relative() const;
};

/// Paper 003's group feature vector P.
struct GroupFeature {
  double d12 = 0.0;    ///< metres: |landmark 2 - landmark 1|
  double d13 = 0.0;    ///< metres: |landmark 3 - landmark 1|
  double angle = 0.0;  ///< radians in (-pi, pi]: signed angle from d12 to d13, anticlockwise positive
};

/// Feature of the landmarks p1, p2, p3 (any common frame; metres).
GroupFeature group_feature(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& p3);

/// A group of three differently coloured sightings of one frame.
struct LandmarkGroup {
  std::array<std::size_t, 3> member{};  ///< indices into the frame's sightings: landmarks 1, 2, 3
  std::array<int, 3> colour{};          ///< their colour ids, increasing
  GroupFeature feature;
};

/// Every group of three sightings with three different colours (C(n, 3) at most), members ordered by
/// increasing colour id. Sightings with a non-finite distance or bearing, or a negative distance, are
/// skipped.
/// Groups are listed in lexicographic order of their sighting indices.
std::vector<LandmarkGroup> form_groups(std::span<const LandmarkSighting> sightings);

/// Matching thresholds (paper 003 gives none; defaults ours, for an omni camera whose distances are
/// good to a few decimetres at the landmarks' range; raise them with the distance noise).
struct GroupMatchParams {
  double max_distance_diff = 0.5;              ///< metres, on |d12| and on |d13| separately
  double max_angle_diff = deg2rad(10.0);       ///< radians, on the signed angle
};

/// True when a and b have the same colours and every feature difference is within the thresholds.
bool groups_match(const LandmarkGroup& a, const LandmarkGroup& b, const GroupMatchParams& p);

/// Normalised feature difference: (dd12 / max_distance_diff)^2 + (dd13 / max_distance_diff)^2 +
/// (dangle / max_angle_diff)^2 (dimensionless; <= 3 for any matching pair).
double feature_cost(const GroupFeature& a, const GroupFeature& b, const GroupMatchParams& p);

/// Matches the current frame's groups to the previous frame's: result[i] is the index of the previous
/// group matched to current[i], or -1. One-to-one; among all pairs that match (groups_match), the pair
/// with the smallest feature_cost is taken first (ties: lower current, then lower previous index).
std::vector<int> match_groups(std::span<const LandmarkGroup> previous, std::span<const LandmarkGroup> current,
                              const GroupMatchParams& p);

/// Fix of one group: `world` holds the global positions (metres) of its landmarks 1, 2, 3, the bearings
/// come from `sightings` (the frame the group was formed in). circle_intersection_003; ok = false with
/// a reason when the geometry is degenerate.
Fix group_fix(const LandmarkGroup& g, std::span<const LandmarkSighting> sightings, const std::array<Eigen::Vector2d, 3>& world);

/// Paper 003's plausible region: the circle whose diameter joins the planned path's start and goal,
/// its radius enlarged by `margin` ("enlarged as needed"). A negative radius means "everywhere".
struct PlausibleRegion {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< metres, global frame
  double radius = -1.0;                              ///< metres; < 0: no restriction

  /// Circle on the diameter start-goal (metres), radius |goal - start| / 2 + margin (margin >= 0, metres).
  static PlausibleRegion from_path(const Eigen::Vector2d& start, const Eigen::Vector2d& goal, double margin = 0.0);
  static PlausibleRegion everywhere() { return {}; }
  /// Inside or on the circle (always true for `everywhere`).
  bool contains(const Eigen::Vector2d& p) const;
};

/// Paper 003, sec. 2.2.
struct VotingParams {
  double position_tol = 0.5;              ///< metres: two fixes agree when closer than this ...
  double heading_tol = deg2rad(10.0);     ///< ... and their headings differ by less than this (radians)
  /// A position outside the plausible region is accepted anyway when the deadlock count (consecutive
  /// frames without an accepted position, before this frame) exceeds this ("more than 3 deadlocks").
  int deadlock_limit = 3;
  /// The paper's pseudo-code compares fix i only with the fixes after it (j > i), so the first member
  /// of a cluster collects all of the cluster's votes and later members fewer. false (default): one
  /// vote per agreeing other fix, before or after (the paper's description: every fix is voted on).
  bool later_only = false;
};

/// Outcome of one frame's vote.
struct VoteResult {
  bool accepted = false;       ///< the paper's visflag: a new position was accepted this frame
  bool forced = false;         ///< accepted although outside the plausible region (deadlock > limit)
  Pose2 position;              ///< position_result after the frame (the previous one when !accepted)
  int votes = 0;               ///< votes of the accepted average; 0 when !accepted
  int deadlock = 0;            ///< the deadlock count after the frame
  std::vector<int> fix_votes;  ///< votes of each fix (itself included)
  /// Indices (into the frame's fixes) of the fixes averaged into the accepted position, the best-voted
  /// fix first; empty when !accepted. Lets a caller split an accepted position's error into the
  /// errors of the fixes it came from (experiments/landmark_maps.cpp, paper 003's voting bound).
  std::vector<int> members;
};

/// Paper 003's voting over the fixes of one frame, with the state it keeps between frames (the last
/// accepted position and the deadlock count). Per frame, for i = 0..n-1 in order:
///   votes_i = 1 + #{j != i (j > i if later_only): |p_j - p_i| < position_tol and |th_j - th_i| < heading_tol};
///   if votes_i > maxvote or nothing accepted yet this frame:
///     average = mean of fix i and its agreeing fixes (circular mean for the heading); maxvote = votes_i;
///     if average in the region or deadlock > deadlock_limit: accept it (position_result = average).
/// Then deadlock = 0 if something was accepted, else deadlock + 1 (a frame without fixes counts too).
class FixVoter {
 public:
  explicit FixVoter(const Pose2& start = Pose2(), const VotingParams& params = {});
  VoteResult vote(std::span<const Pose2> fixes, const PlausibleRegion& region);
  const Pose2& position() const { return position_; }
  int deadlock() const { return deadlock_; }
  const VotingParams& params() const { return params_; }

 private:
  VotingParams params_;
  Pose2 position_;
  int deadlock_ = 0;
};

/// Mean of poses: arithmetic for x, y, circular for theta. Empty input gives the zero pose.
Pose2 mean_pose(std::span<const Pose2> poses);

struct GroupLocalizerParams {
  GroupMatchParams match;
  VotingParams voting;
  /// false: no voting and no plausibility check; the estimate is the mean of the frame's fixes (the
  /// last estimate when there are none). For comparing with and without paper 003's voting.
  bool use_voting = true;
  /// false (paper 003): a group is recognised only when it matches a group of the previous frame, so a
  /// group seen again after a gap (out of range, a missed match) gets new global coordinates from the
  /// current estimate, and estimate errors accumulate with every such restart.
  /// true (our extension): every group ever given coordinates is remembered and the current groups are
  /// matched against all of them (feature from the stored coordinates: the same rigid configuration),
  /// so a group seen again keeps the coordinates it got when first seen.
  bool remember_groups = false;
};

/// A group of the current frame with its global landmark coordinates.
struct TrackedGroup {
  LandmarkGroup group;
  std::array<Eigen::Vector2d, 3> world{};  ///< metres, global frame: landmarks 1, 2, 3
  int id = -1;                             ///< the same across matched frames; new groups get new ids
  int previous = -1;                       ///< index of the group matched (in the previous frame's groups, or
                                           ///< in the memory with remember_groups), -1 when new
  Fix fix;                                 ///< this frame's fix (only for matched groups; !ok otherwise)
};

struct GroupFrameResult {
  std::vector<TrackedGroup> groups;
  std::vector<Pose2> fixes;  ///< the ok fixes, in group order (the voter's input)
  VoteResult vote;           ///< with use_voting = false: accepted = !fixes.empty(), votes = 0
  Pose2 estimate;            ///< the robot position after this frame
};

/// The whole of paper 003's scheme, frame by frame: form groups, match them with the previous frame
/// (or with every group seen so far, remember_groups),
/// fix each matched group from its carried global coordinates and this frame's bearings, vote (or
/// average), then give unmatched (new) groups global coordinates from the new estimate and this
/// frame's sightings (distance and bearing). A group seen for the first time gives no fix. The global
/// frame is the one `start` is expressed in (the paper: the robot's start pose, so start = (0, 0, 0)).
class GroupLocalizer {
 public:
  explicit GroupLocalizer(const Pose2& start = Pose2(), const GroupLocalizerParams& params = {});
  GroupFrameResult update(std::span<const LandmarkSighting> sightings, const PlausibleRegion& region);
  const Pose2& estimate() const { return estimate_; }

 private:
  GroupLocalizerParams params_;
  FixVoter voter_;
  Pose2 estimate_;
  std::vector<TrackedGroup> candidates_;  ///< the previous frame's groups, or every group seen (remember_groups)
  int next_id_ = 0;
};

}  // namespace omniloc::landmarks
