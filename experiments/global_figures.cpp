#include "experiments/global_figures.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>

#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"
#include "harness/camera_perception.hpp"
#include "harness/field_picture.hpp"
#include "harness/plot.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "localization/grid_global.hpp"
#include "localization/mcl.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::Event;
using harness::FieldPicture;
using harness::FrameConditions;
using harness::PerceptionOutput;
using harness::RunDirectory;
using harness::Scenario;
using harness::Series;
using harness::line_plot;
using harness::load_scenario;
using harness::png_bytes;
using harness::world_at;

namespace {
std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}
}  // namespace

int run_global_figures(const ExperimentArgs& args, std::ostream& out) {
  const Scenario sc = load_scenario(std::string(OMNILOC_SOURCE_DIR) + "/scenarios/paper/kidnap_000.json");
  const Event& kidnap = sc.events.front();
  const int robot = kidnap.robot;
  // The robot stands at the first kidnap target, camera uncovered: what the localizer sees then.
  const double t = kidnap.t + kidnap.duration();
  const sim::WorldState ws = world_at(sc, t, args.seed);
  const Pose2 truth = ws.robot(robot)->pose;
  CameraPerception perception(sc, args.seed);
  const FieldMap map(sc.field, 0.05, "results/cache");
  RunDirectory dir(args.out_dir);

  // Figure 7 / 9: the MTi heading is the true heading plus the robot profile's 1 degree of noise.
  Rng mti = Rng::stream(args.seed, "mti");
  const double heading = wrap_angle(truth.theta + mti.normal(0.0, deg2rad(1.0)));
  const PerceptionOutput po = perception.observe(ws, robot, t, FrameConditions{});
  GridGlobalParams gp;
  gp.record_traces = true;
  const GridSearchRecord rec = grid_search(sc.field, map, po.obs.line_points, heading, gp);

  FieldPicture pic(sc.field, 30.0, 1.3);
  cv::Mat f7 = pic.canvas();
  double lo = 1e9, hi = -1e9;
  for (const auto& s : rec.samples)
    if (s.pass == 0) lo = std::min(lo, s.error), hi = std::max(hi, s.error);
  const int half = static_cast<int>(0.35 * gp.spacing * pic.scale());
  for (const auto& s : rec.samples) {
    if (s.pass != 0) continue;
    const int g = static_cast<int>(255.0 * (s.error - lo) / std::max(1e-12, hi - lo));  // dark = small E_k
    const cv::Point c = pic.px(s.x, s.y);
    cv::rectangle(f7, c - cv::Point(half, half), c + cv::Point(half, half), cv::Scalar(g, g, g), -1);
  }
  for (const auto& cand : rec.candidates) {
    if (cand.pass != 0) continue;
    cv::circle(f7, pic.px(cand.start.x, cand.start.y), half + 4, cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
    cv::line(f7, pic.px(cand.start.x, cand.start.y), pic.px(cand.result.x, cand.result.y), cv::Scalar(0, 200, 255), 2, cv::LINE_AA);
  }
  cv::drawMarker(f7, pic.px(truth.x, truth.y), cv::Scalar(255, 80, 0), cv::MARKER_TILTED_CROSS, 22, 3);
  const auto& chosen = rec.candidates[static_cast<std::size_t>(rec.chosen)];
  cv::drawMarker(f7, pic.px(chosen.result.x, chosen.result.y), cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 22, 2);
  {
    // Colour bar: the grey level of a sample against its E_k (dark = small, as the samples).
    cv::Mat bar(f7.rows, 110, CV_8UC3, cv::Scalar(255, 255, 255));
    const int top = 30, bottom = f7.rows - 30;
    for (int y = top; y <= bottom; ++y) {
      const int g = static_cast<int>(255.0 * (bottom - y) / std::max(1, bottom - top));
      cv::line(bar, {10, y}, {34, y}, cv::Scalar(g, g, g));
    }
    cv::rectangle(bar, {10, top}, {34, bottom}, cv::Scalar(0, 0, 0));
    cv::putText(bar, fmt("%.3f", hi), {40, top + 10}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::putText(bar, fmt("%.3f", lo), {40, bottom}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::putText(bar, "E_k", {40, (top + bottom) / 2}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::hconcat(f7, bar, f7);
  }
  cv::Mat head(34, f7.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(head, "Paper 000 fig. 7: E_k per grid sample (dark = small); red: best 5 and their RPROP paths; blue x: truth", {6, 22},
              cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
  cv::vconcat(head, f7, f7);
  dir.write("figure7_grid_errors.png", png_bytes(f7));

  std::vector<Series> traces;
  Json cands = Json::array();
  out << "global_figures: robot at (" << fmt("%.2f, %.2f, %.3f", truth.x, truth.y, truth.theta) << "), "
      << po.obs.line_points.size() << " line points, MTi heading " << fmt("%.3f", heading) << " rad\n";
  out << "pass | start x cm  start y cm | result x cm result y cm  theta rad | error after RPROP | iterations\n";
  for (std::size_t k = 0; k < rec.candidates.size(); ++k) {
    const auto& c = rec.candidates[k];
    Series s;
    s.label = fmt("(%.0f, %.0f) cm", 100 * c.start.x, 100 * c.start.y);
    for (std::size_t i = 0; i < c.trace.size(); ++i) {
      s.x.push_back(static_cast<double>(i));
      s.y.push_back(c.trace[i]);
    }
    if (c.pass == 0) traces.push_back(s);
    out << fmt("%4.0f | ", c.pass) << fmt("%10.0f  %10.0f | ", 100 * c.start.x, 100 * c.start.y)
        << fmt("%11.0f %11.0f %10.3f | ", 100 * c.result.x, 100 * c.result.y, c.result.theta) << fmt("%17.4f | ", c.error)
        << c.trace.size() - 1 << (static_cast<int>(k) == rec.chosen ? "  <- chosen" : "") << "\n";
    cands.push_back({{"pass", c.pass}, {"start", {c.start.x, c.start.y, c.start.theta}}, {"result", {c.result.x, c.result.y, c.result.theta}},
                     {"error", c.error}, {"trace", c.trace}});
  }
  dir.write("figure9_rprop_traces.png",
            png_bytes(line_plot(traces, "RPROP from the five best grid samples (paper 000 fig. 9)", "iteration", "mean e(d), c = 0.25 m", true)));
  Json samples = Json::array();
  for (const auto& s : rec.samples) samples.push_back({s.x, s.y, s.error, s.pass});
  const double pos_err = std::hypot(chosen.result.x - truth.x, chosen.result.y - truth.y);
  out << "chosen after " << rec.passes << " pass(es), " << (rec.accepted ? "accepted" : "best of all passes") << ": position error "
      << fmt("%.1f cm, heading error %.3f rad", 100 * pos_err, angle_diff(chosen.result.theta, truth.theta)) << "\n";

  // MCL convergence from a uniform cloud, the robot standing still (zero odometry) at the same place.
  McLLocalizer mcl(sc.field, McLParams{}, derive_seed(args.seed, "mcl"), "results/cache");
  mcl.reset(std::nullopt);
  const int frames[] = {0, 1, 2, 4, 8, 16};
  std::vector<cv::Mat> tiles;
  Json mcl_rows = Json::array();
  Odometry still;
  for (int k = 0, shot = 0; k <= 16; ++k) {
    const double tk = t + k / sc.camera_rate;
    const PerceptionOutput pk = perception.observe(ws, robot, tk, FrameConditions{});
    const Estimate e = mcl.update(pk.obs, still, wrap_angle(truth.theta + mti.normal(0.0, deg2rad(1.0))));
    const double err = std::hypot(e.pose.x - truth.x, e.pose.y - truth.y);
    mcl_rows.push_back({{"frame", k}, {"spread_m", e.extra.count("spread_m") ? e.extra.at("spread_m") : 0.0}, {"error_m", err}, {"mode", e.mode}});
    if (shot < 6 && k == frames[shot]) {
      cv::Mat tile = FieldPicture(sc.field, 14.0, 1.0).canvas();
      FieldPicture small(sc.field, 14.0, 1.0);
      for (const auto& p : mcl.particles()) cv::circle(tile, small.px(p.pose.x, p.pose.y), 1, cv::Scalar(0, 0, 230), -1);
      cv::drawMarker(tile, small.px(truth.x, truth.y), cv::Scalar(255, 80, 0), cv::MARKER_TILTED_CROSS, 14, 2);
      cv::putText(tile, "after frame " + std::to_string(k) + fmt(": error %.2f m", err), {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1,
                  cv::LINE_AA);
      tiles.push_back(tile);
      ++shot;
    }
  }
  cv::Mat row1, row2, grid;
  cv::hconcat(std::vector<cv::Mat>(tiles.begin(), tiles.begin() + 3), row1);
  cv::hconcat(std::vector<cv::Mat>(tiles.begin() + 3, tiles.end()), row2);
  cv::vconcat(row1, row2, grid);
  dir.write("mcl_particles.png", png_bytes(grid));
  out << "MCL (600 particles, uniform start, compass headings): error after frames 0/1/2/4/8/16:";
  for (int f : frames) out << fmt(" %.2f", mcl_rows[static_cast<std::size_t>(f)]["error_m"].get<double>());
  out << " m\n";

  Json j{{"truth", {truth.x, truth.y, truth.theta}}, {"heading", heading}, {"line_points", po.obs.line_points.size()},
         {"grid", {{"spacing", gp.spacing}, {"passes", rec.passes}, {"accepted", rec.accepted}, {"chosen", rec.chosen}}},
         {"samples", samples}, {"candidates", cands}, {"position_error_m", pos_err}, {"mcl", mcl_rows}};
  dir.write("global_figures.json", j.dump(1) + "\n");
  dir.commit();
  out << "figures: " << dir.final_dir() << "/{figure7_grid_errors,figure9_rprop_traces,mcl_particles}.png\n";
  return 0;
}

}  // namespace omniloc::experiments
