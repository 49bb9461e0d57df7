#pragma once
// Kidnapped-robot metrics (papers 000 / 002): after each kidnap, when did the localizer find the
// true pose again, did it stand behind a wrong (or mirrored) pose, and how accurate was it after
// recovery. Computed from truth and estimates, like every metric, in the harness only.
#include <vector>

#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "harness/scoring/error_stats.hpp"

namespace omniloc::harness {

struct ScoredFrame {
  double t = 0.0;
  Pose2 truth, est;
  bool valid = false;
};

struct RecoveryCriteria {
  double pos_tol = 0.3;       ///< metres: "recovered" means error under this ...
  double theta_tol = 0.2;     ///< ... and this (radians) ...
  double hold = 1.0;          ///< ... for this long (seconds)
  double wrong_pos = 1.0;     ///< metres: a valid estimate this far off ...
  double wrong_theta = 0.5;   ///< ... or this far in heading ...
  double wrong_hold = 1.0;    ///< ... for this long is a false recovery
  double mirror_pos = 0.6;    ///< metres / ...
  double mirror_theta = 0.4;  ///< ... radians from the point-mirrored truth (-x, -y, theta + pi): a mirror pose
};

struct Episode {
  double t_kidnap = 0.0;  ///< seconds
  double t_uncover = 0.0; ///< camera uncovered: vision can start
  double t_end = 0.0;     ///< next kidnap or end of run
};

struct EpisodeResult {
  bool recovered = false;
  double recovery_time = 0.0;  ///< seconds of vision (from uncover) until the error stayed under the tolerances
  bool false_recovery = false;
  bool mirrored = false;
  std::vector<FrameError> after;  ///< errors from recovery to the episode end
};

EpisodeResult score_episode(const std::vector<ScoredFrame>& frames, const Episode& e, const RecoveryCriteria& c = {});

/// The tracking phase of a run with disruptions (kidnaps, covered camera): every valid frame outside
/// [disruption start, recovery), where recovery is that of score_episode (the episode end when the
/// localizer never recovered). These are the frames the papers' error tables describe; the frames
/// while the robot was carried or blind, and until it found itself again, are the recovery metrics'.
struct PhaseSplit {
  std::vector<FrameError> tracking;                  ///< errors of the valid frames kept
  std::size_t frames = 0;                            ///< every frame kept, with an estimate or not
  std::vector<std::pair<double, double>> excluded;   ///< [from, to) seconds, one per disruption ("to" past the run's end: never recovered)
  double excluded_s = 0.0;                           ///< total excluded time within the run, seconds
};
PhaseSplit split_tracking_phase(const std::vector<ScoredFrame>& frames, const std::vector<Episode>& disruptions,
                                const RecoveryCriteria& c = {});

/// Summary over all episodes: {"episodes", "recovered", "recovered_fraction", "recovery_time_s":
/// {"median", "mean", "max"}, "false_recoveries", "mirrored", "after_recovery": ErrorSummary}.
Json recovery_summary(const std::vector<EpisodeResult>& results);

}  // namespace omniloc::harness
