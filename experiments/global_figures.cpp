#include "experiments/global_figures.hpp"

#include <cmath>
#include <cstdio>
#include <ostream>

#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"
#include "experiments/report_format.hpp"
#include "harness/cache/cache_dirs.hpp"
#include "harness/camera_perception.hpp"
#include "experiments/field_picture.hpp"
#include "experiments/plot.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "localization/mcl.hpp"
#include "core/install_paths.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::Event;
using harness::FrameConditions;
using harness::PerceptionOutput;
using harness::RunDirectory;
using harness::Scenario;
using harness::load_scenario;
using harness::world_at;

// --- configuration --------------------------------------------------------------------------------------

GlobalFiguresConfig GlobalFiguresConfig::from_args(const ExperimentArgs& args) {
  GlobalFiguresConfig c;
  c.scenario_file = (share_dir() / "scenarios/paper/kidnap_000.json").string();
  c.seed = args.seed;
  return c;
}

// --- computation ----------------------------------------------------------------------------------------

const GridSearchRecord::Candidate& GlobalFiguresResult::chosen() const { return record.candidates[static_cast<std::size_t>(record.chosen)]; }

double GlobalFiguresResult::position_error() const { return std::hypot(chosen().result.x - truth.x, chosen().result.y - truth.y); }

namespace {

/// MCL convergence from a uniform cloud, the robot standing still (zero odometry) where the scene puts it.
void mcl_convergence(const GlobalFiguresConfig& cfg, const Scenario& sc, const sim::WorldState& ws, int robot, double t, CameraPerception& perception,
                     Rng& mti, GlobalFiguresResult& r) {
  McLLocalizer mcl(sc.field, McLParams{}, derive_seed(cfg.seed, "mcl"), harness::build_cache_dir("fieldmaps"));
  mcl.reset(std::nullopt);
  Odometry still;
  std::size_t shot = 0;
  for (int k = 0; k <= cfg.mcl_frames; ++k) {
    const double tk = t + k / sc.camera_rate;
    const PerceptionOutput pk = perception.observe(ws, robot, tk, FrameConditions{});
    const Estimate e = mcl.update(pk.obs, still, wrap_angle(r.truth.theta + mti.normal(0.0, deg2rad(1.0))));
    const double err = std::hypot(e.pose.x - r.truth.x, e.pose.y - r.truth.y);
    r.mcl.push_back({k, e.extra.count("spread_m") ? e.extra.at("spread_m") : 0.0, err, e.mode});
    if (shot < cfg.snapshots.size() && k == cfg.snapshots[shot]) {
      GlobalFiguresResult::Snapshot s{k, err, {}};
      for (const auto& p : mcl.particles()) s.particles.push_back(p.pose);
      r.snapshots.push_back(std::move(s));
      ++shot;
    }
  }
}

}  // namespace

GlobalFiguresResult compute_global_figures(const GlobalFiguresConfig& cfg) {
  const Scenario sc = load_scenario(cfg.scenario_file);
  const Event& kidnap = sc.events.front();
  const int robot = kidnap.robot;
  // The robot stands at the first kidnap target, camera uncovered: what the localizer sees then.
  const double t = kidnap.t + kidnap.duration();
  const sim::WorldState ws = world_at(sc, t, cfg.seed);
  GlobalFiguresResult r;
  r.field = sc.field;
  r.truth = ws.robot(robot)->pose;
  CameraPerception perception(sc, cfg.seed);
  const FieldMap map(sc.field, 0.05, harness::build_cache_dir("fieldmaps"));

  // Figure 7 / 9: the MTi heading is the true heading plus the robot profile's 1 degree of noise.
  Rng mti = Rng::stream(cfg.seed, "mti");
  r.heading = wrap_angle(r.truth.theta + mti.normal(0.0, deg2rad(1.0)));
  const PerceptionOutput po = perception.observe(ws, robot, t, FrameConditions{});
  r.line_points = po.obs.line_points.size();
  r.grid_params.record_traces = true;
  r.record = grid_search(sc.field, map, po.obs.line_points, r.heading, r.grid_params);
  mcl_convergence(cfg, sc, ws, robot, t, perception, mti, r);
  return r;
}

// --- report ---------------------------------------------------------------------------------------------

namespace {

/// Paper 000 figure 7: every first-pass grid sample's E_k as a grey square, the candidates, truth and choice.
cv::Mat figure7(const GlobalFiguresResult& r) {
  FieldPicture pic(r.field, 30.0, 1.3);
  cv::Mat f7 = pic.canvas();
  double lo = 1e9, hi = -1e9;
  for (const auto& s : r.record.samples)
    if (s.pass == 0) lo = std::min(lo, s.error), hi = std::max(hi, s.error);
  const int half = static_cast<int>(0.35 * r.grid_params.spacing * pic.scale());
  for (const auto& s : r.record.samples) {
    if (s.pass != 0) continue;
    const int g = static_cast<int>(255.0 * (s.error - lo) / std::max(1e-12, hi - lo));  // dark = small E_k
    const cv::Point c = pic.px(s.x, s.y);
    cv::rectangle(f7, c - cv::Point(half, half), c + cv::Point(half, half), cv::Scalar(g, g, g), -1);
  }
  for (const auto& cand : r.record.candidates) {
    if (cand.pass != 0) continue;
    cv::circle(f7, pic.px(cand.start.x, cand.start.y), half + 4, cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
    cv::line(f7, pic.px(cand.start.x, cand.start.y), pic.px(cand.result.x, cand.result.y), cv::Scalar(0, 200, 255), 2, cv::LINE_AA);
  }
  cv::drawMarker(f7, pic.px(r.truth.x, r.truth.y), cv::Scalar(255, 80, 0), cv::MARKER_TILTED_CROSS, 22, 3);
  cv::drawMarker(f7, pic.px(r.chosen().result.x, r.chosen().result.y), cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 22, 2);
  {
    // Colour bar: the grey level of a sample against its E_k (dark = small, as the samples).
    cv::Mat bar(f7.rows, 110, CV_8UC3, cv::Scalar(255, 255, 255));
    const int top = 30, bottom = f7.rows - 30;
    for (int y = top; y <= bottom; ++y) {
      const int g = static_cast<int>(255.0 * (bottom - y) / std::max(1, bottom - top));
      cv::line(bar, {10, y}, {34, y}, cv::Scalar(g, g, g));
    }
    cv::rectangle(bar, {10, top}, {34, bottom}, cv::Scalar(0, 0, 0));
    cv::putText(bar, strprintf("%.3f", hi), {40, top + 10}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::putText(bar, strprintf("%.3f", lo), {40, bottom}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::putText(bar, "E_k", {40, (top + bottom) / 2}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
    cv::hconcat(f7, bar, f7);
  }
  cv::Mat head(34, f7.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(head, "Paper 000 fig. 7: E_k per grid sample (dark = small); red: best 5 and their RPROP paths; blue x: truth", {6, 22},
              cv::FONT_HERSHEY_SIMPLEX, 0.42, {20, 20, 20}, 1, cv::LINE_AA);
  cv::vconcat(head, f7, f7);
  return f7;
}

/// The candidates' table to `out`; their RPROP traces (first pass) as the figure 9 series; their JSON.
Json candidates_report(const GlobalFiguresResult& r, std::vector<Series>& traces, std::ostream& out) {
  Json cands = Json::array();
  out << "pass | start x cm  start y cm | result x cm result y cm  theta rad | error after RPROP | iterations\n";
  for (std::size_t k = 0; k < r.record.candidates.size(); ++k) {
    const auto& c = r.record.candidates[k];
    Series s;
    s.label = strprintf("(%.0f, %.0f) cm", 100 * c.start.x, 100 * c.start.y);
    for (std::size_t i = 0; i < c.trace.size(); ++i) {
      s.x.push_back(static_cast<double>(i));
      s.y.push_back(c.trace[i]);
    }
    if (c.pass == 0) traces.push_back(s);
    out << strprintf("%4.0f | ", static_cast<double>(c.pass)) << strprintf("%10.0f  %10.0f | ", 100 * c.start.x, 100 * c.start.y)
        << strprintf("%11.0f %11.0f %10.3f | ", 100 * c.result.x, 100 * c.result.y, c.result.theta) << strprintf("%17.4f | ", c.error)
        << c.trace.size() - 1 << (static_cast<int>(k) == r.record.chosen ? "  <- chosen" : "") << "\n";
    cands.push_back({{"pass", c.pass}, {"start", {c.start.x, c.start.y, c.start.theta}}, {"result", {c.result.x, c.result.y, c.result.theta}},
                     {"error", c.error}, {"trace", c.trace}});
  }
  return cands;
}

/// The particle clouds after the snapshot frames, in two rows of three tiles.
cv::Mat particle_tiles(const GlobalFiguresResult& r) {
  std::vector<cv::Mat> tiles;
  for (const auto& s : r.snapshots) {
    cv::Mat tile = FieldPicture(r.field, 14.0, 1.0).canvas();
    FieldPicture small(r.field, 14.0, 1.0);
    for (const auto& p : s.particles) cv::circle(tile, small.px(p.x, p.y), 1, cv::Scalar(0, 0, 230), -1);
    cv::drawMarker(tile, small.px(r.truth.x, r.truth.y), cv::Scalar(255, 80, 0), cv::MARKER_TILTED_CROSS, 14, 2);
    cv::putText(tile, "after frame " + std::to_string(s.frame) + strprintf(": error %.2f m", s.error_m), {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                {255, 255, 255}, 1, cv::LINE_AA);
    tiles.push_back(tile);
  }
  cv::Mat row1, row2, grid;
  cv::hconcat(std::vector<cv::Mat>(tiles.begin(), tiles.begin() + 3), row1);
  cv::hconcat(std::vector<cv::Mat>(tiles.begin() + 3, tiles.end()), row2);
  cv::vconcat(row1, row2, grid);
  return grid;
}

}  // namespace

void write_global_figures_report(const GlobalFiguresConfig& cfg, const GlobalFiguresResult& r, RunDirectory& dir, std::ostream& out) {
  const auto& chosen = r.chosen();
  dir.write("figure7_grid_errors.png", png_bytes(figure7(r)));
  out << "global_figures: robot at (" << strprintf("%.2f, %.2f, %.3f", r.truth.x, r.truth.y, r.truth.theta) << "), " << r.line_points
      << " line points, MTi heading " << strprintf("%.3f", r.heading) << " rad\n";
  std::vector<Series> traces;
  const Json cands = candidates_report(r, traces, out);
  dir.write("figure9_rprop_traces.png",
            png_bytes(line_plot(traces, "RPROP from the five best grid samples (paper 000 fig. 9)", "iteration", "mean e(d), c = 0.25 m", true)));
  Json samples = Json::array();
  for (const auto& s : r.record.samples) samples.push_back({s.x, s.y, s.error, s.pass});
  out << "chosen after " << r.record.passes << " pass(es), " << (r.record.accepted ? "accepted" : "best of all passes") << ": position error "
      << strprintf("%.1f cm, heading error %.3f rad", 100 * r.position_error(), angle_diff(chosen.result.theta, r.truth.theta)) << "\n";

  dir.write("mcl_particles.png", png_bytes(particle_tiles(r)));
  Json mcl_rows = Json::array();
  for (const auto& m : r.mcl) mcl_rows.push_back({{"frame", m.frame}, {"spread_m", m.spread_m}, {"error_m", m.error_m}, {"mode", m.mode}});
  out << "MCL (600 particles, uniform start, compass headings): error after frames 0/1/2/4/8/16:";
  for (int f : cfg.snapshots) out << strprintf(" %.2f", r.mcl[static_cast<std::size_t>(f)].error_m);
  out << " m\n";

  Json j{{"truth", {r.truth.x, r.truth.y, r.truth.theta}}, {"heading", r.heading}, {"line_points", r.line_points},
         {"grid", {{"spacing", r.grid_params.spacing}, {"passes", r.record.passes}, {"accepted", r.record.accepted}, {"chosen", r.record.chosen}}},
         {"samples", samples}, {"candidates", cands}, {"position_error_m", r.position_error()}, {"mcl", mcl_rows}};
  dir.write("global_figures.json", j.dump(1) + "\n");
  dir.commit();
  out << "figures: " << dir.final_dir() << "/{figure7_grid_errors,figure9_rprop_traces,mcl_particles}.png\n";
}

// --- the experiment -------------------------------------------------------------------------------------

int run_global_figures(const ExperimentArgs& args, std::ostream& out) {
  const GlobalFiguresConfig cfg = GlobalFiguresConfig::from_args(args);
  RunDirectory dir(args.out_dir);  // refuses an unusable output folder before any work
  const GlobalFiguresResult r = compute_global_figures(cfg);
  write_global_figures_report(cfg, r, dir, out);
  return 0;
}

}  // namespace omniloc::experiments
