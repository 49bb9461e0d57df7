#pragma once
// The alternative-pose provider: a per-frame fit of (x, y, theta) to the line points from several
// candidates, after the Falcons' field fit (Falcons-Robocup code, packages/multiCam
// determinePosition; MRA-components localization_vision): a Nelder-Mead simplex on a score looked
// up in a field table, started from the previous frame's candidates (moved by odometry) and from
// fresh restarts, the best few kept for the next frame. Our score is the matcher's robust error
// through the distance map (localization/field_map, localization/match_data_term): the mean of
// e(d) = 1 - c^2 / (c^2 + d^2) over the points (Lauer et al. 2005). Restarts are screened at a wide
// c (a smooth score that many starts reach: paper 000's grid search uses 2.55 m for the same
// reason) and the best refined at a wide then the final c (continuation, as the matcher does).
//
// B-Human's SelfLocator takes such proposals (its "alternative pose" from recent features) into
// its hypothesis set when they disagree with the current estimate; localization/modern/ukf_mh.cpp
// does that with these.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/pose2.hpp"
#include "core/rng.hpp"
#include "localization/field_map.hpp"

namespace omniloc::modern {

struct AlternativePoseParams {
  int pool = 6;               ///< candidates kept from frame to frame (Falcons keep the previous ones)
  int screened = 100;         ///< fresh restarts scored once per search frame
  int refined = 4;            ///< of them, the best refined by the simplex
  double c_wide = 1.0;        ///< m: screening and the first simplex stage
  double c = 0.25;            ///< m: the final stage and the score proposals are compared by
  int max_evaluations = 120;  ///< simplex evaluations per stage
  double step_xy = 0.3;       ///< m: the initial simplex's size in x and y
  double step_theta = 0.15;   ///< rad
  double tolerance = 0.002;   ///< m (and rad): the simplex stops when smaller than this
  double distinct_xy = 0.25;  ///< m: pool candidates closer than this (and distinct_theta) are one
  double distinct_theta = 0.2;  ///< rad
};

struct Candidate {
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  ///< x, y, theta (world frame)
  double score = 1.0;                              ///< mean e(d) at params.c, in [0, 1]
};

/// Mean e(d) of the points (robot frame) at pose q.
double fit_score(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c);

/// Nelder-Mead (reflection 1, expansion 2, contraction 1/2, shrink 1/2) on fit_score from `start`,
/// first at c_wide, then at c. `heading`: when given, theta is held there during the first stage
/// (a compass fixes it; the search is then over x and y only, as paper 000's).
Candidate simplex_fit(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& start, const AlternativePoseParams& p,
                      std::optional<double> heading = std::nullopt);

class AlternativePoses {
 public:
  AlternativePoses(const AlternativePoseParams& p, double half_x, double half_y, std::uint64_t seed);
  void clear() { pool_.clear(); }
  /// Moves the pool by an odometry increment (robot frame).
  void move(const Pose2& delta);
  /// One search round: the pool refined again, `restarts` fresh starts screened (headings from
  /// `heading` when given, else uniform) and the best `params.refined` of them refined; the pool
  /// becomes the best distinct candidates, best first. `extra`: more starts refined as well (the
  /// hypotheses' means).
  const std::vector<Candidate>& search(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading, int restarts,
                                       const std::vector<Eigen::Vector3d>& extra = {});
  const std::vector<Candidate>& pool() const { return pool_; }

 private:
  AlternativePoseParams p_;
  double half_x_, half_y_;
  Rng rng_;
  std::vector<Candidate> pool_;
};

}  // namespace omniloc::modern
