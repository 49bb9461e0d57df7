#pragma once
// The small set of pose hypotheses of B-Human's SelfLocator (bhuman/BHumanCodeRelease,
// Src/Modules/Modeling/SelfLocator): each an unscented Kalman filter with a validity, filtered over
// frames, that says how well its pose has explained the recent line points. The set is kept small
// and clean by merging (two hypotheses in one basin are one), pruning (hypotheses the evidence has
// left behind), and resampling by replacement (a new proposal takes the slot of the least valid
// one: B-Human's sensor resetting; with a handful of Gaussians instead of particles, the
// low-variance draw reduces to giving the weakest slot away).
#include <cstdint>
#include <vector>

#include "localization/modern/ukf_pose.hpp"

namespace omniloc::modern {

struct Hypothesis {
  UkfPose ukf;
  double validity = 0.0;   ///< in [0, 1]: low-pass filtered share of points that fit
  double age = 0.0;        ///< seconds since it was created
  double inliers = 0.0;    ///< the last frame's share of points that fit
  std::vector<double> recent;  ///< the evidence (share, 0 when contradicted) of its last frames, oldest first
  std::uint32_t id = 0;    ///< creation order: ties go to the older one
};

struct HypothesisSetParams {
  int max_hypotheses = 6;
  double merge_xy = 0.25;     ///< m: closer hypotheses are one (within one association corridor)
  double merge_theta = 0.2;   ///< rad
  double prune_validity = 0.1;
  /// Hypotheses this much less valid than the most valid one are pruned: a validity is a filtered
  /// share of points that fit, whose frame-to-frame noise with ~100 points is a few hundredths, so
  /// 0.3 less after prune_age (two validity time constants) has lost on the evidence.
  double prune_gap = 0.3;
  double prune_age = 1.0;     ///< s: younger hypotheses are not pruned (they have not been judged)
};

/// Two poses within (merge_xy, merge_theta) of each other.
bool same_basin(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double xy, double theta);

/// The field's point-mirror twin of a pose: (-x, -y, theta + pi).
Eigen::Vector3d twin(const Eigen::Vector3d& q);

/// Merges hypotheses in one basin: of each such pair the less valid one goes (equal validity: the
/// younger id). With `twins_equal` a hypothesis in the basin of another's twin goes as well (without
/// a compass or goal colours nothing can tell them apart, and two of them would make the output jump).
/// The hypothesis of id `lead` (the reported one; -1 none) goes only to one more valid by
/// `hysteresis`, as it keeps the lead in best(): a merge must not hand the lead over on less.
void merge(std::vector<Hypothesis>& set, const HypothesisSetParams& p, bool twins_equal, std::int64_t lead = -1, double hysteresis = 0.0);

/// Removes hypotheses older than prune_age with validity below prune_validity or more than
/// prune_gap below the most valid one; never the last one.
void prune(std::vector<Hypothesis>& set, const HypothesisSetParams& p);

/// Adds `h`; when the set is full it replaces the least valid one. Returns false (and adds nothing)
/// when the set is full and every member is more valid than `h`.
bool insert(std::vector<Hypothesis>& set, Hypothesis h, const HypothesisSetParams& p);

/// The index of the most valid hypothesis; `current` (an index or -1) keeps the lead unless another
/// is more valid by `hysteresis`. -1 on an empty set.
int best(const std::vector<Hypothesis>& set, int current, double hysteresis);

}  // namespace omniloc::modern
