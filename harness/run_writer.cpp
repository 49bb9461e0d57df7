#include "harness/run_writer.hpp"

#include <cmath>
#include <cstdio>
#include <set>

#include "core/angles.hpp"

namespace omniloc::harness {

namespace {
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
}  // namespace

std::string tum_line(double t, const Pose2& p) {
  char b[160];
  std::snprintf(b, sizeof b, "%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", t, p.x, p.y, std::sin(0.5 * p.theta), std::cos(0.5 * p.theta));
  return b;
}

std::string frames_csv(const std::vector<RobotRecord>& robots, const std::vector<std::vector<FrameBound>>& bounds) {
  std::string csv =
      "t,robot,gt_x,gt_y,gt_theta,est_x,est_y,est_theta,err_x,err_y,err_theta,err_pos,valid,mode,camera_ok,line_points,match_error,contact,"
      "bound_pos_m,bound_heading_rad,pbound_pos_m,pbound_heading_rad";
  std::set<std::string> extra_keys;
  for (const auto& robot : robots)
    for (const auto& r : robot.frames)
      for (const auto& [k, v] : r.extra) extra_keys.insert(k);
  for (const auto& k : extra_keys) csv += "," + k;
  csv += "\n";
  for (std::size_t i = 0; i < robots.size(); ++i)
    for (std::size_t k = 0; k < robots[i].frames.size(); ++k) {
      const RobotRecord& robot = robots[i];
      const FrameRecord& r = robot.frames[k];
      const double ex = r.est.x - r.truth.x, ey = r.est.y - r.truth.y, eth = angle_diff(r.est.theta, r.truth.theta);
      // Without ground truth (a log not made by omniloc) the truth and error cells stay empty.
      const auto t = [&](double v) { return robot.has_truth ? fmt("%.5f", v) : std::string(); };
      csv += fmt("%.4f", r.t) + "," + std::to_string(robot.id) + "," + t(r.truth.x) + "," + t(r.truth.y) + "," + t(r.truth.theta) + "," +
             fmt("%.5f", r.est.x) + "," + fmt("%.5f", r.est.y) + "," + fmt("%.5f", r.est.theta) + "," + t(ex) + "," + t(ey) + "," + t(eth) +
             "," + t(std::hypot(ex, ey)) + "," +
             (r.valid ? "1" : "0") + "," + (r.mode_label.empty() ? std::string(mode_name(r.mode)) : r.mode_label) + "," + (r.camera_ok ? "1" : "0") + "," + std::to_string(r.points) + "," +
             fmt("%.6g", r.match_error) + "," + (r.contact ? "1" : "0");
      const FrameBound* b = i < bounds.size() && k < bounds[i].size() ? &bounds[i][k] : nullptr;
      const auto cell = [](const std::optional<double>& v) { return v ? fmt("%.6g", *v) : std::string(); };
      csv += "," + (b ? cell(b->pos) : std::string()) + "," + (b ? cell(b->heading) : std::string()) + "," + (b ? cell(b->ppos) : std::string()) +
             "," + (b ? cell(b->pheading) : std::string());
      for (const auto& k : extra_keys) {
        auto it = r.extra.find(k);
        csv += "," + (it == r.extra.end() ? std::string() : fmt("%.6g", it->second));
      }
      csv += "\n";
    }
  return csv;
}

std::string timing_csv(const std::vector<RobotRecord>& robots) {
  // compute_ms only when a localizer reported its own time (an external client, docs/protocol.md);
  // an empty cell is a frame it did not report.
  bool compute = false;
  for (const auto& robot : robots)
    for (const auto& r : robot.frames) compute = compute || r.compute_ms.has_value();
  std::string timing = compute ? "t,robot,render_ms,vision_ms,localize_ms,compute_ms\n" : "t,robot,render_ms,vision_ms,localize_ms\n";
  for (const auto& robot : robots)
    for (const auto& r : robot.frames) {
      timing += fmt("%.4f", r.t) + "," + std::to_string(robot.id) + "," + fmt("%.4f", r.render_ms) + "," + fmt("%.4f", r.vision_ms) + "," +
                fmt("%.4f", r.localize_ms);
      if (compute) timing += "," + (r.compute_ms ? fmt("%.4f", *r.compute_ms) : std::string());
      timing += "\n";
    }
  return timing;
}

std::string truth_tum(const RobotRecord& robot) {
  std::string s;
  for (const auto& r : robot.frames) s += tum_line(r.t, r.truth);
  return s;
}

std::string estimate_tum(const RobotRecord& robot) {
  std::string s;
  for (const auto& r : robot.frames)
    if (r.valid) s += tum_line(r.t, r.est);
  return s;
}

}  // namespace omniloc::harness
