// Report of the experiment "cooperative_001". See cooperative_001_report.hpp and docs/cooperative.md.
#include "experiments/cooperative_001_report.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <ostream>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"
#include "experiments/report_format.hpp"
#include "experiments/field_picture.hpp"
#include "experiments/plot.hpp"
#include "harness/run_directory.hpp"
#include "harness/vision_setup.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using harness::camera_tag;

namespace {

/// The published figures of paper 001 this report sets beside ours (NaN when absent).
struct Paper001 {
  Json papers;
  double equal = std::nan(""), weighted = std::nan("");  ///< m, simulated mean error
  double real_before = std::nan(""), real_after = std::nan("");  ///< cm, the real-robot result
  std::string growth_claim = "n/a";
  static Paper001 read() {
    Paper001 p;
    p.papers = read_published();
    p.equal = published_number(p.papers, "001_cooperative_mean_error_mm", "equal_weights") / 1000.0;
    p.weighted = published_number(p.papers, "001_cooperative_mean_error_mm", "weighted") / 1000.0;
    p.real_before = published_number(p.papers, "001_real_mean_error_cm", "before");
    p.real_after = published_number(p.papers, "001_real_mean_error_cm", "after");
    if (p.papers.contains("001_growth_model") && p.papers["001_growth_model"].contains("claim"))
      p.growth_claim = p.papers["001_growth_model"]["claim"].get<std::string>();
    return p;
  }
};

// --- direct-noise mode ----------------------------------------------------------------------------------

std::string intro_md(const Cooperative001Config& c, const CoopRun& run, double ref) {
  std::ostringstream md;
  md << "# cooperative_001: paper 001 simulation\n\n";
  if (!c.description.empty()) md << c.description << "\n\n";
  md << "Description file `" << run.config_file << "`; seed " << run.seed << (run.quick ? " (quick mode)" : "") << "; machine: " << machine_text()
     << ".\n"
     << strprintf("Field %.1f m x %.1f m, ", c.field_length, c.field_width) << c.robots.size() << " robots, ball "
     << strprintf("(%.0f, %.0f) -> (%.0f, %.0f) mm", 1000 * c.ball_start.x(), 1000 * c.ball_start.y(), 1000 * c.ball_end.x(), 1000 * c.ball_end.y())
     << strprintf(" in %.0f mm steps (%d positions, %.3f s per step). ", 1000 * c.ball_step, c.path_positions(), c.step_time) << "Noise model **"
     << to_string(c.noise_model) << "**, sigma " << mm(c.sigma, 0) << " mm"
     << (c.noise_model == CoopNoiseModel::Polar
             ? strprintf(" (bearing sigma %.2f deg = sigma / L_ref, L_ref = %.0f mm)", 180.0 / std::numbers::pi * c.sigma / ref, 1000 * ref)
             : std::string())
     << ".\n\n";
  return md.str();
}

/// 1. Headline table, the real-robot note, the same draws under every noise model, per robot.
std::string headline_md(const Cooperative001Config& c, const CoopRun& run, const CoopDirectResult& d, const Paper001& p) {
  const CoopPathStats& head = d.model(c.noise_model);
  std::ostringstream md;
  md << "## Mean error over the path, " << run.trials.path << " trials, all " << c.robots.size() << " robots (network: latency "
     << c.network.latency << " s, loss " << c.network.loss << ")\n\n"
     << md_header({"estimate", "mean error (mm)", "per-trial std (mm)", "paper (mm)"})
     << md_row({"one robot's own estimate (mean over robots)", mm(head.single.mean()), mm(head.single.per_trial.sd()), "-"})
     << md_row({"Hough fix, equal weights", mm(head.equal.mean()), mm(head.equal.per_trial.sd()), mm(p.equal, 0)})
     << md_row({"Hough fix, K_i = 1/L_i", mm(head.weighted.mean()), mm(head.weighted.per_trial.sd()), mm(p.weighted, 0)})
     << md_row({"paired difference 1/L - equal (mean +- s.e.)", mm(head.diff.mean) + " +- " + mm(head.diff.se()), mm(head.diff.sd()),
                mm(p.weighted - p.equal, 0)})
     << "\n";
  if (!std::isnan(p.real_before))
    md << strprintf("Paper's real-robot result (not simulated here): mean error %.1f cm -> %.1f cm. ", p.real_before, p.real_after)
       << "The paper does not say where its simulated noise enters; the next table runs the same draws through three readings.\n\n";
  md << "Same observations under each noise model (sigma " << mm(c.sigma, 0) << " mm; mean error in mm):\n\n"
     << md_header({"noise model", "where the noise enters", "own estimate", "equal weights", "K = 1/L", "1/L - equal (+- s.e.)"});
  for (const auto& [m, s] : d.by_model) {
    const char* where = m == CoopNoiseModel::Polar       ? "distance N(0, sigma^2), bearing N(0, (sigma/L_ref)^2)"
                        : m == CoopNoiseModel::Cartesian ? "ball position reported by each robot, N(0, sigma^2 I)"
                                                         : "robot's own position, N(0, sigma^2 I); relative sighting exact";
    md << md_row({std::string(to_string(m)) + (m == c.noise_model ? " (headline)" : ""), where, mm(s.single.mean()), mm(s.equal.mean()),
                  mm(s.weighted.mean()), mm(s.diff.mean) + " +- " + mm(s.diff.se())});
  }
  md << "\nPer robot (headline model), own-estimate mean error in mm:";
  for (std::size_t i = 0; i < head.own.size(); ++i) md << strprintf(" robot %d: ", static_cast<int>(i) + 1) << mm(head.own[i].mean());
  md << ".\n\n";
  return md.str();
}

std::string network_row(const Cooperative001Config& c, const char* name, const sim::NetworkConfig& nc, const CoopPathStats& s) {
  const double steps = static_cast<double>(s.trials) * c.path_positions();
  auto status = [&](const char* key) { return s.status_weighted.count(key) ? s.status_weighted.at(key) : 0.0; };
  std::ostringstream r;
  r << "| " << name << strprintf(" (latency %.3g s, jitter %.3g s ", nc.latency, nc.jitter) << sim::to_string(nc.jitter_kind)
    << strprintf(", loss %.2g)", nc.loss) << " | " << strprintf("%.1f %%", 100.0 * s.lost / std::max(1.0, s.sent)) << " | "
    << strprintf("%.2f %%", 100.0 * s.late / std::max(1.0, s.sent)) << " | " << strprintf("%.2f", s.received_sum / steps) << " | "
    << strprintf("%.2f %%", 100.0 * status("single_robot") / steps) << " | " << strprintf("%.2f %%", 100.0 * status("no_observation") / steps) << " | "
    << mm(s.equal.mean()) << " | " << mm(s.weighted.mean()) << " | " << strprintf("%.0f", 1000.0 * (s.age_n > 0 ? s.age_sum / s.age_n : 0.0)) << " | "
    << mm(s.weighted_at_use.mean()) << " |\n";
  return r.str();
}

/// 2. Network: configured vs lossy, fixes used at their stamps.
std::string network_md(const Cooperative001Config& c, const CoopRun& run, const CoopDirectResult& d) {
  std::ostringstream md;
  md << "## Network (headline noise model, " << run.trials.path << " trials; fusion deadline " << c.fusion_deadline << " s after the stamp)\n\n"
     << "Fixes are computed per time stamp from the sightings of that stamp that arrived in time and compared with the ball **at the "
        "stamp**; the last column compares the same fix with the ball when the fix was made (what a robot acting on it without "
        "prediction would see).\n\n"
     << md_header({"network", "lost", "late", "sightings per fix", "single-robot fixes", "no fix", "equal (mm)", "1/L (mm)", "fix age (ms)",
                   "1/L vs ball at fuse time (mm)"})
     << network_row(c, "configured", c.network, d.model(c.noise_model)) << network_row(c, "lossy", c.lossy_network, d.lossy) << "\n";
  return md.str();
}

/// 3. Error against the number of robots: markdown, robots_vs_error.{csv,png}; returns its JSON.
Json robots_report(const Cooperative001Config& c, const CoopRun& run, const CoopDirectResult& d, std::ostream& md, RunDirectory& dir) {
  md << "## Error against the number of robots (paper fig. 10), " << run.trials.per_subset
     << " trials per subset, mean over **every subset** of that size (and the first k robots of the list)\n\n"
     << md_header({"robots", "subsets", "equal, all subsets (mm)", "1/L, all subsets (mm)", "equal, first k (mm)", "1/L, first k (mm)",
                   "1/L median, all subsets (mm)", "degenerate fixes"});
  std::string csv = "robots,subsets,trials_per_subset,equal_all_subsets_mm,weighted_all_subsets_mm,equal_first_k_mm,weighted_first_k_mm,degenerate_fraction\n";
  Series s_eq{"equal, all subsets", {}, {}}, s_w{"1/L, all subsets", {}, {}}, s_eqf{"equal, first k", {}, {}}, s_wf{"1/L, first k", {}, {}};
  Json robots_json = Json::array();
  for (const CoopRobotCount& r : d.robots_vs_error) {
    md << md_row({std::to_string(r.robots), std::to_string(r.subsets), mm(r.equal_all), mm(r.weighted_all), mm(r.equal_first), mm(r.weighted_first),
                  mm(r.weighted_median), strprintf("%.2f %%", 100.0 * r.degenerate_fraction)});
    csv += strprintf("%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.5f\n", r.robots, r.subsets, run.trials.per_subset, 1000 * r.equal_all, 1000 * r.weighted_all,
                     1000 * r.equal_first, 1000 * r.weighted_first, r.degenerate_fraction);
    for (Series* se : {&s_eq, &s_w, &s_eqf, &s_wf}) se->x.push_back(r.robots);
    s_eq.y.push_back(1000 * r.equal_all);
    s_w.y.push_back(1000 * r.weighted_all);
    s_eqf.y.push_back(1000 * r.equal_first);
    s_wf.y.push_back(1000 * r.weighted_first);
    robots_json.push_back({{"robots", r.robots}, {"subsets", r.subsets}, {"equal_all_mm", 1000 * r.equal_all}, {"weighted_all_mm", 1000 * r.weighted_all},
                           {"equal_first_k_mm", 1000 * r.equal_first}, {"weighted_first_k_mm", 1000 * r.weighted_first},
                           {"weighted_median_all_mm", 1000 * r.weighted_median}, {"degenerate_fraction", r.degenerate_fraction}});
  }
  md << "\nWith one robot both weightings give that robot's own estimate (bearing and distance). Two robots whose lines "
        "to the ball meet at a small angle give a long error ellipse along the lines, hence the large means (and the gap to the median) "
        "at 2 robots. Degenerate fixes (lines within about "
        "1.15 degrees of each other) fall back to the weighted mean of the robots' own estimates and are included in the means.\n\n";
  dir.write("robots_vs_error.csv", csv);
  dir.write("robots_vs_error.png",
            png_bytes(line_plot({s_eq, s_w, s_eqf, s_wf}, "Mean error vs number of robots (paper 001 fig. 10), noise " + std::string(to_string(c.noise_model)),
                                "number of robots", "mean error (mm)")));
  return robots_json;
}

/// 4. Growth-model benchmark: markdown; returns its JSON (with the verdict on the paper's claim).
Json growth_report(const CoopGrowth& g, const Paper001& p, std::ostream& md) {
  Json growth_json = Json::object();
  md << "## Growth-model benchmark (paper 5.3), " << g.runs << " paired Monte Carlo runs, 50 steps, 100 particles, N_th = 50\n\n"
     << md_header({"filter", "mean RMSE", "std", "median"});
  for (const auto& f : g.filters) {
    md << "| " << to_string(f.kind) << strprintf(" | %.3f | %.3f | %.3f |\n", f.mean, f.sd, f.median);
    growth_json[to_string(f.kind)] = {{"mean", f.mean}, {"std", f.sd}, {"median", f.median}};
  }
  auto paired = [&](const CoopGrowth::Paired& d) {
    growth_json[std::string(to_string(d.a)) + "_minus_" + to_string(d.b)] = {{"mean", d.mean}, {"se", d.se}, {"a_lower", d.a_lower}, {"runs", g.runs}};
    return strprintf("%.3f +- %.3f (", d.mean, d.se) + to_string(d.a) + strprintf(" lower in %d of %d runs)", d.a_lower, g.runs);
  };
  const std::string d_mf = paired(g.mfbpf_minus_fbpf), d_fp = paired(g.fbpf_minus_pf);
  const double dm = g.mfbpf_minus_fbpf.mean, dse = g.mfbpf_minus_fbpf.se;
  const double z = dse > 0.0 ? dm / dse : 0.0;
  const std::string verdict = z < -2.0  ? strprintf("reproduced: MFBPF is lower by %.3f (%.1f standard errors)", -dm, -z)
                              : z < 0.0 ? strprintf("not established: MFBPF is lower by %.3f, only %.1f standard errors", -dm, -z)
                                        : strprintf("not reproduced: MFBPF is not lower (MFBPF - FBPF = %+.3f, %.1f standard errors)", dm, z);
  md << "\nPaired differences (mean +- standard error): MFBPF - FBPF = " << d_mf << "; FBPF - PF = " << d_fp << ".\n"
     << "Paper's claim: " << p.growth_claim << " (one run shown). Here: **" << verdict << "**.\n\n";
  growth_json["verdict"] = verdict;
  return growth_json;
}

/// 5. Tracking: markdown; returns its JSON.
Json tracking_report(const Cooperative001Config& c, const CoopTracking& t, std::ostream& md) {
  const auto& trackers = coop_trackers();
  const int K = t.steps;
  // mm; the mean over all steps or (settled) over the steps from `settle` on
  auto mean_mm = [](const std::array<double, 4>& a, bool settled) { return settled ? 1000 * a[2] / std::max(1.0, a[3]) : 1000 * a[0] / std::max(1.0, a[1]); };
  md << "## Tracking (" << t.trials << " trials; mean position error in mm over all " << K << " steps, in brackets over steps " << t.settle << "-"
     << K - 1 << ")\n\n"
     << "Trackers: constant-velocity model, dt " << c.step_time << " s, accel_sigma " << c.accel_sigma << " m/s^2, " << c.particles
     << " particles; obs_sigma per input = its per-axis RMS error measured in the path trials; prior at the first input, velocity std 2 m/s. "
        "'own' inputs are one robot's raw sighting (no cooperation); the lossy-network input is used in stamp order.\n\n";
  std::vector<std::string> columns{"tracker"}, sigmas{"obs_sigma (mm)"};
  for (const auto& in : t.inputs) {
    columns.push_back(in.name);
    sigmas.push_back(mm(in.obs_sigma, 0));
  }
  md << md_header(columns) << md_row(sigmas);
  Json tracking_json = Json::object();
  for (std::size_t tk = 0; tk <= trackers.size(); ++tk) {
    const std::string tname = tk ? trackers[tk - 1] : std::string("input itself (no tracker)");
    std::vector<std::string> row{tname};
    for (std::size_t in = 0; in < t.inputs.size(); ++in) {
      const auto& a = t.acc[in][tk];
      row.push_back(strprintf("%.0f (%.0f)", mean_mm(a, false), mean_mm(a, true)));
      tracking_json[tname][t.inputs[in].name] = {{"mean_mm", mean_mm(a, false)}, {"mean_after_settle_mm", mean_mm(a, true)}};
    }
    md << md_row(row);
  }
  md << "\n";
  return tracking_json;
}

Json path_stats_json(const CoopPathStats& s) {
  return Json{{"trials", s.trials},
              {"own_estimate_mm", 1000 * s.single.mean()},
              {"equal_mm", 1000 * s.equal.mean()},
              {"weighted_mm", 1000 * s.weighted.mean()},
              {"weighted_minus_equal_mm", 1000 * s.diff.mean},
              {"weighted_minus_equal_se_mm", 1000 * s.diff.se()},
              {"equal_per_trial_std_mm", 1000 * s.equal.per_trial.sd()},
              {"weighted_per_trial_std_mm", 1000 * s.weighted.per_trial.sd()},
              {"weighted_vs_ball_at_fuse_time_mm", 1000 * s.weighted_at_use.mean()},
              {"lost_fraction", s.lost / std::max(1.0, s.sent)},
              {"late_fraction", s.late / std::max(1.0, s.sent)},
              {"status_weighted", s.status_weighted}};
}

cv::Mat field_figure(const Cooperative001Config& c, const CoopTrial& tr) {
  const double s = 110.0;  // px per metre
  const int m = 30;
  const int W = static_cast<int>(c.field_length * s) + 2 * m, H = static_cast<int>(c.field_width * s) + 2 * m + 30;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  auto px = [&](const Eigen::Vector2d& p) { return cv::Point(static_cast<int>(m + p.x() * s), static_cast<int>(H - m - p.y() * s)); };
  cv::rectangle(img, px({0, 0}), px({c.field_length, c.field_width}), cv::Scalar(60, 140, 60), 2);
  cv::line(img, px(c.ball_start), px(c.ball_end), cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  for (std::size_t k = 0; k < tr.fixes.size(); ++k) {
    if (usable(tr.fixes[k].equal)) cv::circle(img, px(tr.fixes[k].equal.position), 3, cv::Scalar(200, 120, 40), -1, cv::LINE_AA);
    if (usable(tr.fixes[k].weighted))
      cv::drawMarker(img, px(tr.fixes[k].weighted.position), cv::Scalar(30, 30, 210), cv::MARKER_CROSS, 7, 1, cv::LINE_AA);
  }
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    cv::circle(img, px(c.robots[i]), 9, cv::Scalar(40, 40, 40), 2, cv::LINE_AA);
    cv::putText(img, std::to_string(i + 1), px(c.robots[i]) + cv::Point(11, -8), cv::FONT_HERSHEY_SIMPLEX, 0.5, {20, 20, 20}, 1, cv::LINE_AA);
  }
  cv::putText(img, "robots 1-5 (circles), ball path (line), one trial: equal-weight fixes (blue dots), K = 1/L fixes (red +)", {8, 18},
              cv::FONT_HERSHEY_SIMPLEX, 0.38, {20, 20, 20}, 1, cv::LINE_AA);
  return img;
}

// --- rendered mode --------------------------------------------------------------------------------------

Json fix_json(const CoopFixAcc& a) {
  return Json{{"mean_mm", json_number(1000 * mean(a.errors))},         {"median_mm", json_number(1000 * median(a.errors))},
              {"per_trial_std_mm", json_number(1000 * sd(a.per_trial))}, {"steps", a.steps},
              {"no_fix", a.no_fix},                                      {"degenerate", a.degenerate},
              {"single_robot", a.single}};
}

/// Standard error of the mean of `v` (NaN below two values).
double se_of(const std::vector<double>& v) { return v.size() > 1 ? sd(v) / std::sqrt(static_cast<double>(v.size())) : std::nan(""); }

/// What was rendered and how, and the fix table.
std::string rendered_fixes_md(const Cooperative001Config& c, const CoopRenderedResult& r) {
  const CoopRenderedConfig& g = *c.rendered;
  std::ostringstream md;
  md << "## Rendered mode (" << r.trials << (r.trials == 1 ? " trial" : " trials") << " of the " << r.path_positions << "-step path, "
     << c.robots.size() << " robots, ideal network)\n\n"
     << "Each robot renders its own " << g.camera.width << "x" << g.camera.height << " panorama (camera " << camera_tag(g.camera)
     << ", vibration and pixel noise on), finds the largest orange region (>= " << g.min_area_px
     << " px) with the blob detector through the calibration map and colour table, corrects the nearest-contact distance to the ball "
        "centre (ball radius "
     << mm(g.ball_radius, 0) << " mm, viewpoint " << mm(g.camera.mount_height, 0) << " mm high) and reports the line from its own pose. "
     << "Poses: "
     << (g.pose_source == CoopPoseSource::Matching
             ? strprintf("self-localised with `%s` on %d frames from a start %.0f mm / %.1f deg off", g.localizer["type"].get<std::string>().c_str(),
                         g.selfloc_frames, 1000 * g.start_offset, g.start_heading_offset * 180.0 / kPi)
             : strprintf("ground truth + N(0, (%.0f mm)^2) per axis (no self-localisation)", 1000 * g.pose_sigma))
     << ". Headings: " << (g.headings.empty() ? "each robot faces the middle of the ball path" : "from the file") << ".\n\n";
  md << md_header({"estimate", "mean error (mm)", "median (mm)", "per-trial std (mm)", "no fix"})
     << md_row({"one robot's own estimate (pooled over robots, seen steps)", mm(mean(r.own_err)), mm(median(r.own_err)), "-", "-"});
  auto row = [&](const std::string& name, const CoopFixAcc& a) {
    md << md_row({name, mm(mean(a.errors)), mm(median(a.errors)), mm(sd(a.per_trial)), strprintf("%.1f %%", 100.0 * a.no_fix / std::max(1, a.steps))});
  };
  row("Hough fix, equal weights", r.f_eq);
  row("Hough fix, K_i = 1/L_i", r.f_w);
  row("equal weights, true poses (diagnostic)", r.f_eq_true);
  row("K_i = 1/L_i, true poses (diagnostic)", r.f_w_true);
  const std::string ok_name = strprintf("%d trials without a self-localisation failure", r.trials_ok);
  row("equal weights, " + ok_name, r.f_eq_ok);
  row("K_i = 1/L_i, " + ok_name, r.f_w_ok);
  md << md_row({"paired difference 1/L - equal (per-trial mean +- s.e.)", mm(mean(r.diff_per_trial)) + " +- " + mm(se_of(r.diff_per_trial)), "-", "-", "-"})
     << md_row({"paired difference 1/L - equal, " + ok_name, mm(mean(r.diff_ok)) + " +- " + mm(se_of(r.diff_ok)), "-", "-", "-"}) << "\n";
  return md.str();
}

std::string rendered_selfloc_md(const Cooperative001Config& c, const CoopRenderedResult& r) {
  std::ostringstream md;
  md << "Self-localisation: position error mean " << mm(mean(r.pos_err)) << " mm (median " << mm(median(r.pos_err)) << ", max "
     << mm(r.pos_err.empty() ? std::nan("") : *std::max_element(r.pos_err.begin(), r.pos_err.end())) << "), heading error mean " << deg(mean(r.head_err))
     << (c.rendered->pose_source == CoopPoseSource::Matching ? " deg, from a start " + mm(mean(r.start_pos_err), 0) + " mm off"
                                                             : std::string(" deg (ground truth + noise, no self-localisation)"))
     << ". Per robot (mean position error, mm):";
  for (std::size_t i = 0; i < r.pos_err_robot.size(); ++i) md << strprintf(" %d: ", static_cast<int>(i) + 1) << mm(mean(r.pos_err_robot[i]));
  md << ".\n";
  md << strprintf("Self-localisation failures (position error > %.0f mm): %d of %d robot-trials", 1000 * CoopRenderedResult::kSelflocFail,
                  static_cast<int>(r.failures.size()), r.trials * static_cast<int>(c.robots.size()));
  for (std::size_t f = 0; f < r.failures.size(); ++f) md << (f ? "; " : ": ") << r.failures[f];
  md << ".\n\n";
  return md.str();
}

const char* const kBinNames[CoopSightingStats::kBins] = {"0-1 m", "1-2 m", "2-3 m", "3-4 m", ">= 4 m"};

std::string rendered_sightings_md(const Cooperative001Config& c, const CoopSightingStats& s) {
  const int nr = static_cast<int>(c.robots.size());
  std::ostringstream md;
  md << strprintf("Sightings: %d robot-frames; ball found in %d (%.1f %%), with a distance in %d (%.1f %%); **missed %.1f %%**. ", s.total, s.seen,
                  100.0 * s.seen / std::max(1, s.total), s.usable, 100.0 * s.usable / std::max(1, s.total), 100.0 * s.missed_fraction())
     << strprintf("No orange region: %d with the ball fully behind another robot, %d partly behind one, %d in clear view (too small or lost); "
                  "%d found beyond the calibrated range (bearing only, dropped). Of %d partly occluded sightings %d were still used "
                  "(median abs errors %s mm, %s deg). "
                  "More than one orange region: %d frames; sightings more than 0.5 m off (outliers): %d.\n\n",
                  s.missed_fully_occluded, s.missed_partly_occluded, s.missed_clear, s.no_distance, s.partly_occluded_total, s.partly_occluded_used,
                  mm(median(s.part_d_abs)).c_str(), deg(median(s.part_b_abs)).c_str(), s.multiple_regions, s.outliers)
     << "Missed per robot:";
  for (std::size_t i = 0; i < s.missed_per_robot.size(); ++i) md << strprintf(" %d: %d", static_cast<int>(i) + 1, s.missed_per_robot[i]);
  md << strprintf(" (of %d each).\n\n", s.total / std::max(1, nr));

  md << "Measured sighting errors against the truth (robot frame; distance after the radius correction, signed = measured - true):\n\n"
     << md_header({"true distance", "sightings", "missed", "median abs distance error (mm)", "median signed (mm)", "median abs bearing error (deg)"});
  for (std::size_t b = 0; b < CoopSightingStats::kBins; ++b)
    md << md_row({kBinNames[b], std::to_string(s.bin_total[b]), std::to_string(s.bin_missed[b]), mm(median(s.bin_d_abs[b])), mm(median(s.bin_d_err[b])),
                  deg(median(s.bin_b_abs[b]))});
  md << md_row({"all", std::to_string(s.total), std::to_string(s.total - s.usable), mm(median(s.d_abs)), mm(median(s.d_err)), deg(median(s.b_abs))})
     << "\n"
     << "Without the radius correction (nearest ground contact taken as the ball's distance) the median signed distance error would be "
     << mm(median(s.c_err)) << " mm.\n\n";
  return md.str();
}

/// The rendered robot-count curve: markdown, robots_vs_error_rendered.{csv,png}; returns its JSON.
Json rendered_robots_report(const CoopRenderedResult& r, std::ostream& md, RunDirectory& dir) {
  md << "Error against the number of robots (rendered mode, every subset, all trials and steps; mm):\n\n"
     << md_header({"robots", "equal", "1/L", "1/L median", "no fix"});
  std::string csv = "robots,trials,equal_all_subsets_mm,weighted_all_subsets_mm,weighted_median_mm,no_fix_fraction\n";
  Series s_eq{"rendered, equal", {}, {}}, s_w{"rendered, 1/L", {}, {}};
  Json robots_json = Json::array();
  for (std::size_t k = 1; k < r.sub_n.size(); ++k) {
    const double e = r.sub_n[k] > 0 ? r.sub_eq_sum[k] / r.sub_n[k] : std::nan(""), w = r.sub_n[k] > 0 ? r.sub_w_sum[k] / r.sub_n[k] : std::nan("");
    const double med = median(r.sub_w_err[k]), nf = r.sub_nofix[k] / std::max(1.0, r.sub_steps[k]);
    md << md_row({std::to_string(k), mm(e), mm(w), mm(med), strprintf("%.1f %%", 100.0 * nf)});
    csv += strprintf("%d,%d,%.3f,%.3f,%.3f,%.5f\n", static_cast<int>(k), r.trials, 1000 * e, 1000 * w, 1000 * med, nf);
    s_eq.x.push_back(static_cast<double>(k));
    s_w.x.push_back(static_cast<double>(k));
    s_eq.y.push_back(1000 * e);
    s_w.y.push_back(1000 * w);
    robots_json.push_back({{"robots", k}, {"equal_mm", json_number(1000 * e)}, {"weighted_mm", json_number(1000 * w)},
                           {"weighted_median_mm", json_number(1000 * med)}, {"no_fix_fraction", nf}});
  }
  md << "\n";
  dir.write("robots_vs_error_rendered.csv", csv);
  dir.write("robots_vs_error_rendered.png",
            png_bytes(line_plot({s_eq, s_w}, "Rendered mode: mean error vs number of robots", "number of robots", "mean error (mm)")));
  return robots_json;
}

std::string rendered_trackers_md(const Cooperative001Config& c, const CoopRenderedResult& r) {
  std::ostringstream md;
  if (c.rendered->tracking_repeats > 0) {
    md << "Trackers on the rendered fixes (mean position error over all " << r.path_positions << " steps, mm; obs_sigma = the input's per-axis RMS: "
       << mm(r.tracking_obs_sigma[0], 0) << " mm for 1/L, " << mm(r.tracking_obs_sigma[1], 0) << " mm for equal; particle filters "
       << c.rendered->tracking_repeats << " runs per trial):\n\n"
       << md_header({"tracker", "1/L fix", "equal fix"}) << md_row({"input, no tracker", mm(mean(r.f_w.errors), 0), mm(mean(r.f_eq.errors), 0)});
    for (std::size_t tk = 0; tk < coop_trackers().size(); ++tk)
      md << md_row({coop_trackers()[tk], mm(r.track_mean[0][tk], 0), mm(r.track_mean[1][tk], 0)});
    md << "\n";
  }
  const double ms_per_frame = r.renders ? r.render_ms / r.renders : 0.0;
  md << strprintf("Rendered mode: %d frames rendered at %.1f ms each (llvmpipe); set-up (calibration map and colour table, cached) %.1f s; "
                  "total %.1f s.\n\n",
                  r.renders, ms_per_frame, r.setup_s, r.elapsed_s);
  return md.str();
}

Json rendered_json(const Cooperative001Config& c, const CoopRenderedResult& r, const Json& robots_json) {
  const CoopRenderedConfig& g = *c.rendered;
  const CoopSightingStats& s = r.sightings;
  Json bins_json = Json::array();
  for (std::size_t b = 0; b < CoopSightingStats::kBins; ++b)
    bins_json.push_back({{"bin", kBinNames[b]},
                         {"sightings", s.bin_total[b]},
                         {"missed", s.bin_missed[b]},
                         {"median_abs_distance_error_mm", json_number(1000 * median(s.bin_d_abs[b]))},
                         {"median_signed_distance_error_mm", json_number(1000 * median(s.bin_d_err[b]))},
                         {"median_abs_bearing_error_deg", json_number(median(s.bin_b_abs[b]) * 180.0 / kPi)}});
  Json track_json = Json::object();
  if (g.tracking_repeats > 0)
    for (std::size_t in = 0; in < r.tracking_inputs.size(); ++in)
      for (std::size_t tk = 0; tk < coop_trackers().size(); ++tk) track_json[coop_trackers()[tk]][r.tracking_inputs[in]] = json_number(1000 * r.track_mean[in][tk]);
  return Json{{"trials", r.trials},
              {"path_positions", r.path_positions},
              {"camera", g.camera.to_json()},
              {"pose_source", to_string(g.pose_source)},
              {"min_area_px", g.min_area_px},
              {"own_estimate", {{"mean_mm", json_number(1000 * mean(r.own_err))}, {"median_mm", json_number(1000 * median(r.own_err))}}},
              {"equal", fix_json(r.f_eq)},
              {"weighted", fix_json(r.f_w)},
              {"equal_true_poses", fix_json(r.f_eq_true)},
              {"weighted_true_poses", fix_json(r.f_w_true)},
              {"weighted_minus_equal_mm", json_number(1000 * mean(r.diff_per_trial))},
              {"weighted_minus_equal_no_selfloc_failure_mm", json_number(1000 * mean(r.diff_ok))},
              {"self_localisation",
               {{"position_error_mean_mm", json_number(1000 * mean(r.pos_err))},
                {"position_error_median_mm", json_number(1000 * median(r.pos_err))},
                {"heading_error_mean_deg", json_number(mean(r.head_err) * 180.0 / kPi)},
                {"position_error_max_mm", json_number(r.pos_err.empty() ? std::nan("") : 1000 * *std::max_element(r.pos_err.begin(), r.pos_err.end()))},
                {"start_error_mm", json_number(1000 * mean(r.start_pos_err))},
                {"failures_over_100_mm", r.failures}}},
              {"trials_without_selfloc_failure", r.trials_ok},
              {"equal_no_selfloc_failure", fix_json(r.f_eq_ok)},
              {"weighted_no_selfloc_failure", fix_json(r.f_w_ok)},
              {"sightings",
               {{"total", s.total},
                {"seen", s.seen},
                {"usable", s.usable},
                {"missed_fraction", s.missed_fraction()},
                {"missed_fully_occluded", s.missed_fully_occluded},
                {"missed_partly_occluded", s.missed_partly_occluded},
                {"missed_clear_view", s.missed_clear},
                {"seen_without_distance", s.no_distance},
                {"partly_occluded_total", s.partly_occluded_total},
                {"partly_occluded_used", s.partly_occluded_used},
                {"partly_occluded_median_abs_distance_error_mm", json_number(1000 * median(s.part_d_abs))},
                {"partly_occluded_median_abs_bearing_error_deg", json_number(median(s.part_b_abs) * 180.0 / kPi)},
                {"multiple_regions", s.multiple_regions},
                {"outliers_over_0_5_m", s.outliers},
                {"missed_per_robot", s.missed_per_robot}}},
              {"distance_error",
               {{"median_abs_mm", json_number(1000 * median(s.d_abs))},
                {"median_signed_mm", json_number(1000 * median(s.d_err))},
                {"median_signed_uncorrected_mm", json_number(1000 * median(s.c_err))}}},
              {"bearing_error_median_abs_deg", json_number(median(s.b_abs) * 180.0 / kPi)},
              {"by_distance", bins_json},
              {"robots_vs_error", robots_json},
              {"tracking", track_json},
              {"frames_rendered", r.renders},
              {"render_ms_per_frame", r.renders ? r.render_ms / r.renders : 0.0},
              {"elapsed_s", r.elapsed_s}};
}

/// 6. The rendered mode's markdown section, robots_vs_error_rendered.{csv,png}; returns its JSON.
Json rendered_report(const Cooperative001Config& c, const CoopRenderedResult& r, std::ostream& md, RunDirectory& dir) {
  md << rendered_fixes_md(c, r) << rendered_selfloc_md(c, r) << rendered_sightings_md(c, r.sightings);
  const Json robots_json = rendered_robots_report(r, md, dir);
  md << rendered_trackers_md(c, r);
  return rendered_json(c, r, robots_json);
}

}  // namespace

void write_cooperative_report(const Cooperative001Config& c, const CoopRun& run, const CoopDirectResult& d, const CoopRenderedResult* rendered,
                              RunDirectory& dir, std::ostream& out) {
  const Paper001 paper = Paper001::read();
  const CoopTrials& n = run.trials;
  std::ostringstream md;  // the markdown report, also printed
  md << intro_md(c, run, d.reference_distance) << headline_md(c, run, d, paper) << network_md(c, run, d);
  const Json robots_json = robots_report(c, run, d, md, dir);
  const Json growth_json = growth_report(d.growth, paper, md);
  const Json tracking_json = tracking_report(c, d.tracking, md);
  const Json rendered_json = rendered ? rendered_report(c, *rendered, md, dir) : Json(nullptr);
  md << strprintf("Run time %.1f s.\n", run.elapsed_s);

  Json models_json = Json::object();
  for (const auto& [m, s] : d.by_model) models_json[to_string(m)] = path_stats_json(s);
  Json j{{"experiment", "cooperative_001"},
         {"seed", run.seed},
         {"quick", run.quick},
         {"config_file", run.config_file},
         {"machine", machine_text()},
         {"noise_model", to_string(c.noise_model)},
         {"sigma_m", c.sigma},
         {"reference_distance_m", d.reference_distance},
         {"trials", {{"path", n.path}, {"per_subset", n.per_subset}, {"tracking", n.tracking}, {"growth_model", n.growth_model}}},
         {"paper", {{"equal_mm", 1000 * paper.equal}, {"weighted_mm", 1000 * paper.weighted}}},
         {"headline", path_stats_json(d.model(c.noise_model))},
         {"noise_models", models_json},
         {"lossy_network", path_stats_json(d.lossy)},
         {"robots_vs_error", robots_json},
         {"growth_model", growth_json},
         {"tracking", tracking_json},
         {"rendered", rendered_json},
         {"elapsed_s", run.elapsed_s}};
  if (std::isnan(paper.equal)) j["paper"] = nullptr;
  dir.write("cooperative_001.json", j.dump(1) + "\n");
  dir.write("cooperative_001.md", md.str());
  dir.write("field.png", png_bytes(field_figure(c, d.example)));
  dir.commit();
  out << md.str() << "files: " << dir.final_dir() << "/{cooperative_001.json,cooperative_001.md,robots_vs_error.png,robots_vs_error.csv,field.png"
      << (rendered ? ",robots_vs_error_rendered.png,robots_vs_error_rendered.csv" : "") << "}\n";
}

}  // namespace omniloc::experiments
