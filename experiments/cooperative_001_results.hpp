#pragma once
// What the direct-noise mode of experiment "cooperative_001" measures (cooperative_001.hpp computes
// it, cooperative_001_report.hpp writes it): per-trial fixes, error accumulators, per-model path
// statistics, the robots-vs-error and growth tables.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "experiments/cooperative_001_config.hpp"
#include "experiments/report_format.hpp"
#include "localization/cooperative/hough_ball.hpp"
#include "localization/cooperative/particle_core.hpp"

namespace omniloc::experiments {

/// One path step's fixes, made when the fuser closed the step's stamp.
struct CoopStepFix {
  BallFix equal, weighted;
  double fuse_time = 0.0;  ///< s, when the fuser closed this stamp
  int received = 0;        ///< sightings of this stamp that arrived in time
};

/// One run of the ball along the path.
struct CoopTrial {
  std::vector<CoopStepFix> fixes;                     ///< per step
  std::vector<std::vector<Eigen::Vector2d>> own;      ///< [step][robot]: each robot's own estimate (every robot)
  std::size_t sent = 0, lost = 0, late = 0;
};

/// Pooled error statistics over all fixes of many trials (m).
struct CoopErrorAcc {
  double sum = 0, sumsq = 0, count = 0;
  RunningStat per_trial;  ///< of the per-trial mean errors
  void add_trial(double s, double s2, double n);
  double mean() const;
  double rms_per_axis() const;
};

/// Many trials of the whole path with one noise model and network.
struct CoopPathStats {
  CoopErrorAcc single;             ///< each robot's own estimate, pooled over robots
  std::vector<CoopErrorAcc> own;   ///< per robot
  CoopErrorAcc equal, weighted;    ///< at the stamp
  CoopErrorAcc weighted_at_use;    ///< weighted fix against the ball when the fix was made
  RunningStat diff;                ///< per trial: weighted mean - equal mean
  std::map<std::string, double> status_equal, status_weighted;
  double sent = 0, lost = 0, late = 0, age_sum = 0, age_n = 0, received_sum = 0;
  int trials = 0;
};

/// Error against the number of robots (paper fig. 10), m.
struct CoopRobotCount {
  int robots = 0, subsets = 0;
  double equal_all = 0, weighted_all = 0;      ///< mean over every subset of this size
  double equal_first = 0, weighted_first = 0;  ///< the first `robots` robots of the list
  double weighted_median = 0;                  ///< over every 1/L fix of every subset
  double degenerate_fraction = 0;
};

/// Growth-model benchmark (paper 5.3): bootstrap PF, FBPF and MFBPF on the same trajectories.
struct CoopGrowth {
  struct Filter {
    ParticleFilterKind kind;
    double mean = 0, sd = 0, median = 0;  ///< of the per-run RMSE
  };
  struct Paired {
    ParticleFilterKind a, b;
    double mean = 0, se = 0;  ///< of a - b per run
    int a_lower = 0;          ///< runs where a is lower
  };
  int runs = 0;
  std::vector<Filter> filters;   ///< PF, FBPF, MFBPF
  Paired mfbpf_minus_fbpf, fbpf_minus_pf;
};

/// The four trackers fed with different inputs (fixes and single robots' sightings).
struct CoopTracking {
  struct Input {
    std::string name;
    double obs_sigma;  ///< per-axis RMS error of this input, measured in the path trials (the tracker's R)
  };
  std::vector<Input> inputs;
  int trials = 0, steps = 0, settle = 0;  ///< errors after `settle` steps are also pooled apart
  /// [input][0 = the input itself, 1 + tracker index]: {error sum, count, sum from step settle, count}.
  std::vector<std::vector<std::array<double, 4>>> acc;
};

/// Everything the direct-noise mode measures.
struct CoopDirectResult {
  double reference_distance = 0;  ///< m, the polar model's L_ref
  /// Every noise model (polar, cartesian, robot_pose) on the configured network, the same draws.
  std::vector<std::pair<CoopNoiseModel, CoopPathStats>> by_model;
  CoopPathStats lossy;            ///< the configured noise model on the lossy network
  std::vector<CoopRobotCount> robots_vs_error;  ///< 1 .. number of robots
  CoopGrowth growth;
  CoopTracking tracking;
  CoopTrial example;              ///< trial 0 of the headline set-up (drawn in field.png)
  const CoopPathStats& model(CoopNoiseModel m) const;
};

bool usable(const BallFix& f);  ///< a fix that has a position (not NoObservation)

}  // namespace omniloc::experiments
