#pragma once
// The result files of a run (docs/results.md), made from its records: frames.csv, timing.csv and
// the TUM trajectories gt*.tum / est*.tum (readable by evo).
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "harness/run_record.hpp"
#include "harness/scoring/bound.hpp"

namespace omniloc::harness {

/// TUM trajectory line: "t x y z qx qy qz qw" (z = 0, rotation about z).
std::string tum_line(double t, const Pose2& p);

/// Per frame and robot: truth, estimate, errors, mode, vision statistics and one column for every
/// extra key any robot reported (empty where a frame has none). `bounds`: per robot, each frame's
/// accuracy bound (bound_pos_m, bound_heading_rad, pbound_pos_m, pbound_heading_rad; empty cells
/// where none is finite, and for a robot without one).
std::string frames_csv(const std::vector<RobotRecord>& robots, const std::vector<std::vector<FrameBound>>& bounds = {});
/// Wall-clock stage times per frame: the only file that differs between identical runs.
std::string timing_csv(const std::vector<RobotRecord>& robots);
/// The true and the estimated trajectory (valid frames only) of one robot.
std::string truth_tum(const RobotRecord& robot);
std::string estimate_tum(const RobotRecord& robot);

}  // namespace omniloc::harness
