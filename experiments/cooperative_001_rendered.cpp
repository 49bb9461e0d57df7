// Rendered-image mode of the paper-001 simulation. See cooperative_001_rendered.hpp and
// docs/cooperative.md ("Rendered mode").
#include "experiments/cooperative_001_rendered.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <sstream>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "experiments/cooperative_001.hpp"
#include "experiments/report_format.hpp"
#include "harness/field_picture.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/plot.hpp"
#include "harness/run_directory.hpp"
#include "harness/camera_perception.hpp"
#include "harness/vision_setup.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/cooperative/hough_ball.hpp"
#include "localization/matching.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::LocalizerContext;
using harness::RunDirectory;
using harness::Series;
using harness::VisionConfig;
using harness::camera_tag;
using harness::line_plot;
using harness::localizer_info;
using harness::make_localizer;
using harness::png_bytes;

const char* to_string(CoopPoseSource s) { return s == CoopPoseSource::Matching ? "matching" : "noisy_truth"; }

// --- configuration --------------------------------------------------------------------------------------

CoopRenderedConfig parse_coop_rendered(JsonReader& r, const Cooperative001Config& c) {
  CoopRenderedConfig g;
  r.allow("comment");
  {
    const Json* fj = r.raw("field", true);
    const std::string fp = r.child_path("field");
    if (!fj->is_object()) throw ConfigError(fp, json_brief(*fj), "a field object (docs/scenario.md, \"field\"), field frame");
    // The rendered field must be the field the experiment's coordinates live on: its size comes from
    // /field unless given, and must then agree.
    Json f = *fj;
    if (!f.contains("length")) f["length"] = c.field_length;
    if (!f.contains("width")) f["width"] = c.field_width;
    g.field = Field::from_json(f, fp);
    if (std::abs(g.field.length - c.field_length) > 1e-9)
      throw ConfigError(json_child(fp, "length"), json_brief(f["length"]), "the length of /field (" + std::to_string(c.field_length) + " m)");
    if (std::abs(g.field.width - c.field_width) > 1e-9)
      throw ConfigError(json_child(fp, "width"), json_brief(f["width"]), "the width of /field (" + std::to_string(c.field_width) + " m)");
  }
  if (const Json* cj = r.raw("camera")) g.camera = sim::CameraConfig::from_json(*cj, r.child_path("camera"));
  if (const Json* h = r.raw("headings_deg")) {
    const std::string hp = r.child_path("headings_deg");
    if (!h->is_array() || h->size() != c.robots.size())
      throw ConfigError(hp, json_brief(*h), "an array of " + std::to_string(c.robots.size()) + " robot headings in degrees (one per robot)");
    for (std::size_t i = 0; i < h->size(); ++i) {
      const Json& v = (*h)[i];
      if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > 360.0)
        throw ConfigError(json_child(hp, i), json_brief(v), "a heading in degrees in [-360, 360]");
      g.headings.push_back(v.get<double>() * kPi / 180.0);
    }
  }
  g.trials = static_cast<int>(r.integer("trials", 30, 1, 100000));
  g.quick_trials = static_cast<int>(r.integer("quick_trials", 1, 1, 100000));
  g.min_area_px = static_cast<int>(r.integer("min_area_px", 6, 1, 100000));
  g.ball_radius = r.positive("ball_radius", 0.11, 1.0);
  g.robot_radius = r.positive("robot_radius", 0.26, 2.0);
  g.robot_height = r.positive("robot_height", 0.8, 3.0);
  g.tracking_repeats = static_cast<int>(r.integer("tracking_repeats", 20, 0, 10000));
  if (auto s = r.object("self_localisation")) {
    s->allow("comment");
    g.pose_source = s->string("source", std::string("matching"), {"matching", "noisy_truth"}) == "matching" ? CoopPoseSource::Matching
                                                                                                            : CoopPoseSource::NoisyTruth;
    if (const Json* l = s->raw("localizer")) {
      const std::string lp = s->child_path("localizer");
      if (!l->is_object() || !l->contains("type") || !(*l)["type"].is_string())
        throw ConfigError(lp, json_brief(*l), "a localizer object {\"type\": ..., params}");
      (void)localizer_info((*l)["type"].get<std::string>(), json_child(lp, "type"));  // unknown types fail here, naming the path
      g.localizer = *l;
    }
    g.selfloc_frames = static_cast<int>(s->integer("frames", 15, 1, 10000));
    g.start_offset = s->number("start_offset", 0.3, 0.0, 5.0);
    g.start_heading_offset = s->number("start_heading_offset_deg", 10.0, 0.0, 180.0) * kPi / 180.0;
    g.pose_sigma = s->number("pose_sigma", 0.05, 0.0, 5.0);
    s->finish();
  }
  r.finish();
  const Eigen::Vector2d half(0.5 * c.field_length, 0.5 * c.field_width);
  for (std::size_t i = 0; i < c.robots.size(); ++i)
    if (!g.field.inside_floor(c.robots[i] - half, g.robot_radius))
      throw ConfigError(json_child("/robots", i), "robot " + std::to_string(i + 1),
                        "a robot whose footprint fits on the rendered field's floor (inside the walls)");
  return g;
}

// --- measurement ----------------------------------------------------------------------------------------

Eigen::Vector2d RenderedBallSighting::position() const { return distance * Eigen::Vector2d(std::cos(bearing), std::sin(bearing)); }

double ball_centre_distance(double d, double h, double r) {
  // Vertical plane through the mirror axis and the ball: viewpoint (0, h), ball centre (D, r).
  // The tangent ray through (0, h) and the floor point (d, 0) is the line h x + d y - h d = 0; the
  // ball touches it from above, so (h D + d r - h d) / sqrt(h^2 + d^2) = r.
  return d + r * (std::sqrt(h * h + d * d) - d) / h;
}

RenderedBallSighting ball_sighting_from_blobs(const std::vector<Blob>& blobs, int min_area_px, double mount_height, double ball_radius) {
  RenderedBallSighting s;
  const Blob* best = nullptr;
  for (const Blob& b : blobs) {
    if (b.colour != kBallOrange || b.kind != Blob::Kind::kRegion || b.area_px < min_area_px) continue;
    ++s.regions;
    // The largest region: a split ball (a robot in front of part of it) or an orange speck elsewhere
    // is smaller than the ball's main part.
    if (!best || b.area_px > best->area_px) best = &b;
  }
  if (!best) return s;
  s.seen = true;
  s.bearing = best->bearing;
  s.area_px = best->area_px;
  s.has_distance = best->has_distance;
  if (s.has_distance) {
    s.contact_distance = best->distance;
    s.distance = ball_centre_distance(best->distance, mount_height, ball_radius);
  }
  return s;
}

// --- the run --------------------------------------------------------------------------------------------

namespace {

/// Ground truth for the report only: is the ball (partly) behind another robot as seen by `obs`?
/// 0 = clear, 1 = partly (the robot's footprint disc overlaps the ball's angular extent), 2 = fully.
int occlusion_class(const std::vector<Eigen::Vector2d>& robots, std::size_t obs, const Eigen::Vector2d& ball, double robot_r, double ball_r) {
  const Eigen::Vector2d o = robots[obs];
  const Eigen::Vector2d d = ball - o;
  const double L = d.norm();
  if (L < 1e-9) return 0;
  const Eigen::Vector2d u = d / L;
  int worst = 0;
  for (std::size_t j = 0; j < robots.size(); ++j) {
    if (j == obs) continue;
    const Eigen::Vector2d q = robots[j] - o;
    const double along = q.dot(u);
    if (along <= 0.0 || along >= L) continue;  // not between the observer and the ball
    const double perp = std::abs(u.x() * q.y() - u.y() * q.x());
    // Compare at the ball's distance: the robot's disc subtends robot_r / along, the ball ball_r / L.
    const double robot_half = std::asin(std::min(1.0, robot_r / q.norm()));
    const double ball_half = std::asin(std::min(1.0, ball_r / L));
    const double sep = std::atan2(perp, along);
    if (sep + ball_half <= robot_half) return 2;
    if (sep < robot_half + ball_half) worst = 1;
  }
  return worst;
}

struct FixAcc {
  std::vector<double> errors;     ///< every usable fix's error, m
  std::vector<double> per_trial;  ///< per-trial mean error, m
  double sum_sq = 0;              ///< for the per-axis RMS
  int steps = 0, no_fix = 0, degenerate = 0, single = 0;
  double trial_sum = 0;
  int trial_n = 0;
  void add(const BallFix& f, const Eigen::Vector2d& B) {
    ++steps;
    if (f.status == BallFix::Status::NoObservation) {
      ++no_fix;
      return;
    }
    if (f.status == BallFix::Status::Degenerate) ++degenerate;
    if (f.status == BallFix::Status::SingleRobot) ++single;
    const double e = (f.position - B).norm();
    errors.push_back(e);
    sum_sq += e * e;
    trial_sum += e;
    ++trial_n;
  }
  void end_trial() {
    if (trial_n > 0) per_trial.push_back(trial_sum / trial_n);
    trial_sum = 0;
    trial_n = 0;
  }
  double rms_per_axis() const { return errors.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(errors.size()) / 2.0); }
};

Json fix_json(const FixAcc& a) {
  return Json{{"mean_mm", json_number(1000 * mean(a.errors))},         {"median_mm", json_number(1000 * median(a.errors))},
              {"per_trial_std_mm", json_number(1000 * sd(a.per_trial))}, {"steps", a.steps},
              {"no_fix", a.no_fix},                              {"degenerate", a.degenerate},
              {"single_robot", a.single}};
}

}  // namespace

Json run_cooperative_rendered(const Cooperative001Config& c, int trials, std::uint64_t seed, std::ostream& md, RunDirectory& dir,
                              std::ostream* progress) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  const CoopRenderedConfig& g = *c.rendered;
  const Eigen::Vector2d half(0.5 * c.field_length, 0.5 * c.field_width);  // paper frame -> field frame: p - half
  const int K = c.path_positions();
  const int nr = static_cast<int>(c.robots.size());
  const auto nru = static_cast<std::size_t>(nr);

  // Off-line set-up as a team does it (cached in results/cache): mirror calibration and colour table
  // for this camera and this field, then the robot-side detectors.
  VisionConfig vc;
  vc.scan.line_width = g.field.line_width;
  vc.blobs_detect = "on";
  vc.blobs.colours = {kBallOrange};
  vc.blobs.edge_colours.clear();
  vc.blobs.min_area_px = g.min_area_px;
  vc.blob_edge_colours_given = true;  // the ball only: no goal edges
  CameraPerception rig(g.camera, g.field, vc, seed);
  sim::PanoramicCamera& cam = rig.camera();
  const BlobDetector& blobs = *rig.blob_detector();
  const LineDetector& lines = rig.detector();
  const auto t_setup = Clock::now();

  // True poses (field frame). Default heading: each robot faces the middle of the ball path, as a
  // robot watching the play would (the paper does not give headings).
  std::vector<Pose2> truth(nru);
  std::vector<Eigen::Vector2d> robots_world(nru);  // paper frame, for geometry below
  const Eigen::Vector2d mid = 0.5 * (c.ball_start + c.ball_end);
  for (std::size_t i = 0; i < nru; ++i) {
    const Eigen::Vector2d p = c.robots[i];
    const double h = g.headings.empty() ? std::atan2(mid.y() - p.y(), mid.x() - p.x()) : g.headings[i];
    truth[i] = Pose2(p.x() - half.x(), p.y() - half.y(), h);
    robots_world[i] = p;
  }
  auto world_at = [&](const Eigen::Vector2d& ball_paper, double t) {
    sim::WorldState w;
    w.t = t;
    for (std::size_t i = 0; i < nru; ++i) {
      sim::RobotState r;
      r.id = static_cast<int>(i);
      r.team = 0;
      r.pose = truth[i];
      r.radius = g.robot_radius;
      r.height = g.robot_height;
      w.robots.push_back(r);
    }
    w.ball.position = ball_paper - half;
    w.ball.radius = g.ball_radius;
    w.has_ball = true;
    return w;
  };

  std::unique_ptr<Localizer> loc;
  if (g.pose_source == CoopPoseSource::Matching) {
    LocalizerContext ctx;
    ctx.field = &g.field;
    ctx.seed = derive_seed(seed, "rendered/localizer");
    ctx.cache_dir = "results/cache";
    loc = make_localizer(g.localizer, "/rendered/self_localisation/localizer", ctx);
  }

  // Accumulators.
  double render_ms = 0;
  int renders = 0;
  std::vector<double> pos_err, head_err, start_pos_err;           // self-localisation, per robot and trial
  std::vector<std::vector<double>> pos_err_robot(nru);
  std::vector<double> d_err, d_abs, c_err, b_abs;                 // per usable sighting: distance (corrected, contact), bearing
  std::vector<double> part_d_abs, part_b_abs;                     // the same for sightings with the ball partly behind a robot
  constexpr int kBins = 5;                                          // true distance 0-1, 1-2, 2-3, 3-4, >= 4 m
  std::vector<std::vector<double>> bin_d_abs(kBins), bin_d_err(kBins), bin_b_abs(kBins);
  int bin_missed[kBins] = {0, 0, 0, 0, 0}, bin_total[kBins] = {0, 0, 0, 0, 0};
  int n_sightings = 0, n_seen = 0, n_usable = 0, n_no_distance = 0, n_multi = 0, n_outlier = 0;
  int miss_full = 0, miss_partial = 0, miss_clear = 0, seen_partial = 0, partial_total = 0;
  std::vector<int> missed_robot(nru, 0);
  FixAcc f_eq, f_w, f_eq_true, f_w_true;
  // A robot whose self-localisation ends more than this far from the truth counts as a failure; the
  // fixes are also reported over the trials without any (to separate the two effects).
  constexpr double kSelflocFail = 0.1;  // m
  FixAcc f_eq_ok, f_w_ok;
  std::vector<std::string> failures;  // "trial t robot i: e mm, h deg"
  int trials_ok = 0;
  std::vector<double> diff_per_trial, diff_ok;  // per trial: 1/L mean - equal mean (all trials; without a self-localisation failure)
  std::vector<double> own_err;
  std::vector<std::vector<double>> own_err_robot(nru);
  // Robot-count curve: every subset, every trial, every step (no extra rendering: the same sightings).
  std::vector<double> sub_eq_sum(nru + 1), sub_w_sum(nru + 1), sub_n(nru + 1), sub_nofix(nru + 1), sub_steps(nru + 1);
  std::vector<std::vector<double>> sub_w_err(nru + 1);
  // Fix sequences for the trackers: [trial][step].
  std::vector<std::vector<std::optional<Eigen::Vector2d>>> seq_w, seq_eq;

  HoughBallConfig eq_cfg, w_cfg;
  eq_cfg.weighting = BallWeighting::Equal;
  w_cfg.weighting = BallWeighting::InverseDistance;

  for (int t = 0; t < trials; ++t) {
    // One camera stream per robot and trial (vibration, pixel noise), used for its self-localisation
    // frames and then its path frames.
    std::vector<Rng> cam_rng;
    for (int i = 0; i < nr; ++i) cam_rng.push_back(cooperative_trial_rng(seed, "rendered/camera/" + std::to_string(i), t));
    Rng start_rng = cooperative_trial_rng(seed, "rendered/start", t);

    // 1. Self-localisation: robots stand still, the ball lies at the path's start.
    std::vector<Pose2> est(nru);
    for (std::size_t i = 0; i < nru; ++i) {
      if (g.pose_source == CoopPoseSource::NoisyTruth) {
        est[i] = Pose2(truth[i].x + g.pose_sigma * start_rng.normal(), truth[i].y + g.pose_sigma * start_rng.normal(), truth[i].theta);
        start_pos_err.push_back((est[i].translation() - truth[i].translation()).norm());
      } else {
        const double a = start_rng.uniform(-kPi, kPi);
        const double s = start_rng.uniform() < 0.5 ? -1.0 : 1.0;
        const Pose2 start(truth[i].x + g.start_offset * std::cos(a), truth[i].y + g.start_offset * std::sin(a),
                          truth[i].theta + s * g.start_heading_offset);
        start_pos_err.push_back(g.start_offset);
        loc->reset(start);
        // The robot knows its start is only rough: widen the filter's prior to the start error,
        // otherwise the matching's Kalman filter trusts the wrong start for many frames.
        if (auto* m = dynamic_cast<MatchingLocalizer*>(loc.get())) {
          const double sxy = std::max(0.05, g.start_offset), sth = std::max(0.02, g.start_heading_offset);
          m->filter().reset(start, Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal());
        }
        Estimate e;
        for (int f = 0; f < g.selfloc_frames; ++f) {
          const double tf = -c.step_time * (g.selfloc_frames - f);  // before the ball starts rolling at t = 0
          const sim::WorldState w = world_at(c.ball_start, tf);
          const auto r0 = Clock::now();
          const Image img = cam.render(w, static_cast<int>(i), g.camera.initial, cam_rng[i]);
          render_ms += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
          ++renders;
          Odometry odo;
          odo.t = tf;  // standing still: zero motion
          e = loc->update(lines.observe(img, tf), odo, std::nullopt);
        }
        est[i] = e.pose;
      }
      const double pe = (est[i].translation() - truth[i].translation()).norm();
      pos_err.push_back(pe);
      pos_err_robot[i].push_back(pe);
      if (pe > kSelflocFail)
        failures.push_back(strprintf("trial %d robot %d: %.0f mm, %.1f deg", t + 1, static_cast<int>(i) + 1, 1000 * pe,
                              std::abs(wrap_angle(est[i].theta - truth[i].theta)) * 180.0 / kPi));
      head_err.push_back(std::abs(wrap_angle(est[i].theta - truth[i].theta)));
    }

    bool trial_ok = true;
    for (std::size_t i = 0; i < nru; ++i) trial_ok = trial_ok && (est[i].translation() - truth[i].translation()).norm() <= kSelflocFail;
    trials_ok += trial_ok;

    // 2. The ball rolls; every robot renders, detects and reports.
    std::vector<std::vector<std::optional<BallLine>>> L(static_cast<std::size_t>(K), std::vector<std::optional<BallLine>>(nru));
    std::vector<std::vector<std::optional<BallLine>>> Ltrue = L;
    for (int k = 0; k < K; ++k) {
      const double tk = k * c.step_time;
      const Eigen::Vector2d B = c.ball_at(tk);
      const sim::WorldState w = world_at(B, tk);
      for (std::size_t i = 0; i < nru; ++i) {
        const auto r0 = Clock::now();
        const Image img = cam.render(w, static_cast<int>(i), g.camera.initial, cam_rng[i]);
        render_ms += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
        ++renders;
        const RenderedBallSighting s = ball_sighting_from_blobs(blobs.detect(img), g.min_area_px, g.camera.mount_height, g.ball_radius);
        // Truth, for scoring only.
        const Eigen::Vector2d rel = truth[i].inverse_transform(B - half);
        const double D = rel.norm(), beta = std::atan2(rel.y(), rel.x());
        const int occ = occlusion_class(robots_world, i, B, g.robot_radius, g.ball_radius);
        const int bin = std::min(kBins - 1, static_cast<int>(D));
        ++n_sightings;
        ++bin_total[bin];
        if (occ == 1) ++partial_total;
        if (s.seen) ++n_seen;
        if (s.regions > 1) ++n_multi;
        if (s.seen && !s.has_distance) ++n_no_distance;
        if (!s.seen || !s.has_distance) {
          ++bin_missed[bin];
          ++missed_robot[i];
          if (!s.seen) (occ == 2 ? miss_full : occ == 1 ? miss_partial : miss_clear)++;
          continue;
        }
        if (occ == 1) ++seen_partial;
        ++n_usable;
        const double de = s.distance - D, be = wrap_angle(s.bearing - beta);
        if ((s.position() - rel).norm() > 0.5) ++n_outlier;  // something else orange, or a badly cut ball
        d_err.push_back(de);
        d_abs.push_back(std::abs(de));
        c_err.push_back(s.contact_distance - D);
        b_abs.push_back(std::abs(be));
        if (occ == 1) {
          part_d_abs.push_back(std::abs(de));
          part_b_abs.push_back(std::abs(be));
        }
        bin_d_abs[static_cast<std::size_t>(bin)].push_back(std::abs(de));
        bin_d_err[static_cast<std::size_t>(bin)].push_back(de);
        bin_b_abs[static_cast<std::size_t>(bin)].push_back(std::abs(be));
        BallLine l;
        l.stamp = tk;
        l.robot = est[i].translation() + half;  // back to the paper frame
        l.ball_estimate = est[i].transform(s.position()) + half;
        L[static_cast<std::size_t>(k)][i] = l;
        BallLine lt = l;
        lt.robot = truth[i].translation() + half;
        lt.ball_estimate = truth[i].transform(s.position()) + half;
        Ltrue[static_cast<std::size_t>(k)][i] = lt;
        const double oe = (l.ball_estimate - B).norm();
        own_err.push_back(oe);
        own_err_robot[i].push_back(oe);
      }
    }

    // 3. Fixes: all robots (estimated and, as a diagnostic, true poses), and every subset.
    seq_w.emplace_back(static_cast<std::size_t>(K));
    seq_eq.emplace_back(static_cast<std::size_t>(K));
    for (int k = 0; k < K; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const Eigen::Vector2d B = c.ball_at(k * c.step_time);
      std::vector<BallLine> all, all_true;
      for (std::size_t i = 0; i < nru; ++i)
        if (L[ku][i]) {
          all.push_back(*L[ku][i]);
          all_true.push_back(*Ltrue[ku][i]);
        }
      const BallFix fe = hough_ball_fix(all, eq_cfg), fw = hough_ball_fix(all, w_cfg);
      f_eq.add(fe, B);
      f_w.add(fw, B);
      f_eq_true.add(hough_ball_fix(all_true, eq_cfg), B);
      f_w_true.add(hough_ball_fix(all_true, w_cfg), B);
      if (trial_ok) {
        f_eq_ok.add(fe, B);
        f_w_ok.add(fw, B);
      }
      if (fw.status != BallFix::Status::NoObservation) seq_w.back()[ku] = fw.position;
      if (fe.status != BallFix::Status::NoObservation) seq_eq.back()[ku] = fe.position;
      for (unsigned mask = 1; mask < (1u << nr); ++mask) {
        std::vector<BallLine> sub;
        std::size_t size = 0;
        for (std::size_t i = 0; i < nru; ++i)
          if (mask & (1u << i)) {
            ++size;
            if (L[ku][i]) sub.push_back(*L[ku][i]);
          }
        ++sub_steps[size];
        const BallFix se = hough_ball_fix(sub, eq_cfg), sw = hough_ball_fix(sub, w_cfg);
        if (sw.status == BallFix::Status::NoObservation) {
          ++sub_nofix[size];
          continue;
        }
        sub_eq_sum[size] += (se.position - B).norm();
        const double ew = (sw.position - B).norm();
        sub_w_sum[size] += ew;
        sub_w_err[size].push_back(ew);
        ++sub_n[size];
      }
    }
    const double m_eq = f_eq.trial_n ? f_eq.trial_sum / f_eq.trial_n : std::nan(""), m_w = f_w.trial_n ? f_w.trial_sum / f_w.trial_n : std::nan("");
    if (std::isfinite(m_eq) && std::isfinite(m_w)) {
      diff_per_trial.push_back(m_w - m_eq);
      if (trial_ok) diff_ok.push_back(m_w - m_eq);
    }
    for (FixAcc* a : {&f_eq, &f_w, &f_eq_true, &f_w_true, &f_eq_ok, &f_w_ok}) a->end_trial();
    if (progress)
      *progress << strprintf("rendered mode: trial %d/%d done, %.0f s\n", t + 1, trials, std::chrono::duration<double>(Clock::now() - t_start).count())
                << std::flush;
  }

  // 4. Trackers on the rendered fixes (no rendering; obs_sigma = the input's measured per-axis RMS).
  const std::vector<std::string> trackers = {"kf", "pf", "fbpf", "mfbpf"};
  struct TrackIn {
    std::string name;
    const std::vector<std::vector<std::optional<Eigen::Vector2d>>>* seq;
    double obs_sigma;
  };
  const std::vector<TrackIn> tin = {{"1/L fix", &seq_w, f_w.rms_per_axis()}, {"equal fix", &seq_eq, f_eq.rms_per_axis()}};
  Json track_json = Json::object();
  std::vector<std::vector<double>> track_mean(tin.size(), std::vector<double>(trackers.size(), std::nan("")));
  if (g.tracking_repeats > 0)
    for (std::size_t in = 0; in < tin.size(); ++in)
      for (std::size_t tk = 0; tk < trackers.size(); ++tk) {
        double sum = 0, n = 0;
        const int reps = trackers[tk] == "kf" ? 1 : g.tracking_repeats;  // the Kalman filter draws nothing
        for (std::size_t tr = 0; tr < tin[in].seq->size(); ++tr) {
          const auto& z = (*tin[in].seq)[tr];
          std::optional<Eigen::Vector2d> first;
          for (const auto& zz : z)
            if (zz) {
              first = *zz;
              break;
            }
          if (!first) continue;
          for (int rep = 0; rep < reps; ++rep) {
            auto tracker = make_coop_tracker(c, trackers[tk], tin[in].obs_sigma, *first);  // as the direct-noise tracking table
            Rng frng = cooperative_trial_rng(seed, "rendered/tracking/" + trackers[tk] + "/" + tin[in].name, static_cast<int>(tr) * 10007 + rep);
            for (int k = 0; k < K; ++k) {
              const Eigen::Vector2d B = c.ball_at(k * c.step_time);
              sum += (tracker->step(z[static_cast<std::size_t>(k)], frng).state.head<2>() - B).norm();
              n += 1;
            }
          }
        }
        track_mean[in][tk] = n > 0 ? sum / n : std::nan("");
        track_json[trackers[tk]][tin[in].name] = json_number(1000 * track_mean[in][tk]);
      }

  // 5. Report.
  const double elapsed = std::chrono::duration<double>(Clock::now() - t_start).count();
  const double setup_s = std::chrono::duration<double>(t_setup - t_start).count();
  const double ms_per_frame = renders ? render_ms / renders : 0.0;
  const double missed_frac = n_sightings ? 1.0 - static_cast<double>(n_usable) / n_sightings : 0.0;
  const char* bin_names[kBins] = {"0-1 m", "1-2 m", "2-3 m", "3-4 m", ">= 4 m"};

  md << "## Rendered mode (" << trials << (trials == 1 ? " trial" : " trials") << " of the " << K << "-step path, " << nr
     << " robots, ideal network)\n\n"
     << "Each robot renders its own " << g.camera.width << "x" << g.camera.height << " panorama (camera " << camera_tag(g.camera)
     << ", vibration and pixel noise on), finds the largest orange region (>= " << g.min_area_px
     << " px) with the blob detector through the calibration map and colour table, corrects the nearest-contact distance to the ball "
        "centre (ball radius "
     << mm(g.ball_radius, 0) << " mm, viewpoint " << mm(g.camera.mount_height, 0) << " mm high) and reports the line from its own pose. "
     << "Poses: " << (g.pose_source == CoopPoseSource::Matching
                          ? strprintf("self-localised with `%s` on %d frames from a start %.0f mm / %.1f deg off", g.localizer["type"].get<std::string>().c_str(),
                               g.selfloc_frames, 1000 * g.start_offset, g.start_heading_offset * 180.0 / kPi)
                          : strprintf("ground truth + N(0, (%.0f mm)^2) per axis (no self-localisation)", 1000 * g.pose_sigma))
     << ". Headings: " << (g.headings.empty() ? "each robot faces the middle of the ball path" : "from the file") << ".\n\n";

  md << "| estimate | mean error (mm) | median (mm) | per-trial std (mm) | no fix |\n|---|---|---|---|---|\n"
     << "| one robot's own estimate (pooled over robots, seen steps) | " << mm(mean(own_err)) << " | " << mm(median(own_err)) << " | - | - |\n";
  auto row = [&](const char* name, const FixAcc& a) {
    md << "| " << name << " | " << mm(mean(a.errors)) << " | " << mm(median(a.errors)) << " | " << mm(sd(a.per_trial)) << " | "
       << strprintf("%.1f %%", 100.0 * a.no_fix / std::max(1, a.steps)) << " |\n";
  };
  row("Hough fix, equal weights", f_eq);
  row("Hough fix, K_i = 1/L_i", f_w);
  row("equal weights, true poses (diagnostic)", f_eq_true);
  row("K_i = 1/L_i, true poses (diagnostic)", f_w_true);
  const std::string ok_name = strprintf("%d trials without a self-localisation failure", trials_ok);
  row(("equal weights, " + ok_name).c_str(), f_eq_ok);
  row(("K_i = 1/L_i, " + ok_name).c_str(), f_w_ok);
  md << "| paired difference 1/L - equal (per-trial mean +- s.e.) | " << mm(mean(diff_per_trial)) << " +- "
     << mm(diff_per_trial.size() > 1 ? sd(diff_per_trial) / std::sqrt(static_cast<double>(diff_per_trial.size())) : std::nan("")) << " | - | - | - |\n"
     << "| paired difference 1/L - equal, " << ok_name << " | " << mm(mean(diff_ok)) << " +- "
     << mm(diff_ok.size() > 1 ? sd(diff_ok) / std::sqrt(static_cast<double>(diff_ok.size())) : std::nan("")) << " | - | - | - |\n\n";

  md << "Self-localisation: position error mean " << mm(mean(pos_err)) << " mm (median " << mm(median(pos_err)) << ", max "
     << mm(pos_err.empty() ? std::nan("") : *std::max_element(pos_err.begin(), pos_err.end())) << "), heading error mean " << deg(mean(head_err))
     << (g.pose_source == CoopPoseSource::Matching ? " deg, from a start " + mm(mean(start_pos_err), 0) + " mm off"
                                                   : std::string(" deg (ground truth + noise, no self-localisation)"))
     << ". Per robot (mean position error, mm):";
  for (std::size_t i = 0; i < nru; ++i) md << strprintf(" %d: ", static_cast<int>(i) + 1) << mm(mean(pos_err_robot[i]));
  md << ".\n";
  md << strprintf("Self-localisation failures (position error > %.0f mm): %d of %d robot-trials", 1000 * kSelflocFail, static_cast<int>(failures.size()),
           trials * nr);
  for (std::size_t f = 0; f < failures.size(); ++f) md << (f ? "; " : ": ") << failures[f];
  md << ".\n\n";

  md << strprintf("Sightings: %d robot-frames; ball found in %d (%.1f %%), with a distance in %d (%.1f %%); **missed %.1f %%**. ", n_sightings, n_seen,
           100.0 * n_seen / std::max(1, n_sightings), n_usable, 100.0 * n_usable / std::max(1, n_sightings), 100.0 * missed_frac)
     << strprintf("No orange region: %d with the ball fully behind another robot, %d partly behind one, %d in clear view (too small or lost); "
           "%d found beyond the calibrated range (bearing only, dropped). Of %d partly occluded sightings %d were still used "
           "(median abs errors %s mm, %s deg). "
           "More than one orange region: %d frames; sightings more than 0.5 m off (outliers): %d.\n\n",
           miss_full, miss_partial, miss_clear, n_no_distance, partial_total, seen_partial, mm(median(part_d_abs)).c_str(),
           deg(median(part_b_abs)).c_str(), n_multi, n_outlier)
     << "Missed per robot:";
  for (std::size_t i = 0; i < nru; ++i) md << strprintf(" %d: %d", static_cast<int>(i) + 1, missed_robot[i]);
  md << strprintf(" (of %d each).\n\n", n_sightings / std::max(1, nr));

  md << "Measured sighting errors against the truth (robot frame; distance after the radius correction, signed = measured - true):\n\n"
     << "| true distance | sightings | missed | median abs distance error (mm) | median signed (mm) | median abs bearing error (deg) |\n"
     << "|---|---|---|---|---|---|\n";
  Json bins_json = Json::array();
  for (int b = 0; b < kBins; ++b) {
    const auto bu = static_cast<std::size_t>(b);
    md << "| " << bin_names[b] << " | " << bin_total[b] << " | " << bin_missed[b] << " | " << mm(median(bin_d_abs[bu])) << " | "
       << mm(median(bin_d_err[bu])) << " | " << deg(median(bin_b_abs[bu])) << " |\n";
    bins_json.push_back({{"bin", bin_names[b]},
                         {"sightings", bin_total[b]},
                         {"missed", bin_missed[b]},
                         {"median_abs_distance_error_mm", json_number(1000 * median(bin_d_abs[bu]))},
                         {"median_signed_distance_error_mm", json_number(1000 * median(bin_d_err[bu]))},
                         {"median_abs_bearing_error_deg", json_number(median(bin_b_abs[bu]) * 180.0 / kPi)}});
  }
  md << "| all | " << n_sightings << " | " << n_sightings - n_usable << " | " << mm(median(d_abs)) << " | " << mm(median(d_err)) << " | "
     << deg(median(b_abs)) << " |\n\n"
     << "Without the radius correction (nearest ground contact taken as the ball's distance) the median signed distance error would be "
     << mm(median(c_err)) << " mm.\n\n";

  // Robot-count curve.
  md << "Error against the number of robots (rendered mode, every subset, all trials and steps; mm):\n\n"
     << "| robots | equal | 1/L | 1/L median | no fix |\n|---|---|---|---|---|\n";
  std::string csv = "robots,trials,equal_all_subsets_mm,weighted_all_subsets_mm,weighted_median_mm,no_fix_fraction\n";
  Series s_eq{"rendered, equal", {}, {}}, s_w{"rendered, 1/L", {}, {}};
  Json robots_json = Json::array();
  for (std::size_t k = 1; k <= nru; ++k) {
    const double e = sub_n[k] > 0 ? sub_eq_sum[k] / sub_n[k] : std::nan(""), w = sub_n[k] > 0 ? sub_w_sum[k] / sub_n[k] : std::nan("");
    const double med = median(sub_w_err[k]), nf = sub_nofix[k] / std::max(1.0, sub_steps[k]);
    md << "| " << k << " | " << mm(e) << " | " << mm(w) << " | " << mm(med) << " | " << strprintf("%.1f %%", 100.0 * nf) << " |\n";
    csv += strprintf("%d,%d,%.3f,%.3f,%.3f,%.5f\n", static_cast<int>(k), trials, 1000 * e, 1000 * w, 1000 * med, nf);
    s_eq.x.push_back(static_cast<double>(k));
    s_w.x.push_back(static_cast<double>(k));
    s_eq.y.push_back(1000 * e);
    s_w.y.push_back(1000 * w);
    robots_json.push_back({{"robots", k}, {"equal_mm", json_number(1000 * e)}, {"weighted_mm", json_number(1000 * w)}, {"weighted_median_mm", json_number(1000 * med)}, {"no_fix_fraction", nf}});
  }
  md << "\n";
  dir.write("robots_vs_error_rendered.csv", csv);
  dir.write("robots_vs_error_rendered.png",
            png_bytes(line_plot({s_eq, s_w}, "Rendered mode: mean error vs number of robots", "number of robots", "mean error (mm)")));

  if (g.tracking_repeats > 0) {
    md << "Trackers on the rendered fixes (mean position error over all " << K << " steps, mm; obs_sigma = the input's per-axis RMS: "
       << mm(tin[0].obs_sigma, 0) << " mm for 1/L, " << mm(tin[1].obs_sigma, 0) << " mm for equal; particle filters " << g.tracking_repeats
       << " runs per trial):\n\n| tracker | 1/L fix | equal fix |\n|---|---|---|\n"
       << "| input, no tracker | " << mm(mean(f_w.errors), 0) << " | " << mm(mean(f_eq.errors), 0) << " |\n";
    for (std::size_t tk = 0; tk < trackers.size(); ++tk)
      md << "| " << trackers[tk] << " | " << mm(track_mean[0][tk], 0) << " | " << mm(track_mean[1][tk], 0) << " |\n";
    md << "\n";
  }
  md << strprintf("Rendered mode: %d frames rendered at %.1f ms each (llvmpipe); set-up (calibration map and colour table, cached) %.1f s; "
           "total %.1f s.\n\n",
           renders, ms_per_frame, setup_s, elapsed);

  Json j{{"trials", trials},
         {"path_positions", K},
         {"camera", g.camera.to_json()},
         {"pose_source", to_string(g.pose_source)},
         {"min_area_px", g.min_area_px},
         {"own_estimate", {{"mean_mm", json_number(1000 * mean(own_err))}, {"median_mm", json_number(1000 * median(own_err))}}},
         {"equal", fix_json(f_eq)},
         {"weighted", fix_json(f_w)},
         {"equal_true_poses", fix_json(f_eq_true)},
         {"weighted_true_poses", fix_json(f_w_true)},
         {"weighted_minus_equal_mm", json_number(1000 * mean(diff_per_trial))},
         {"weighted_minus_equal_no_selfloc_failure_mm", json_number(1000 * mean(diff_ok))},
         {"self_localisation",
          {{"position_error_mean_mm", json_number(1000 * mean(pos_err))},
           {"position_error_median_mm", json_number(1000 * median(pos_err))},
           {"heading_error_mean_deg", json_number(mean(head_err) * 180.0 / kPi)},
           {"position_error_max_mm", json_number(pos_err.empty() ? std::nan("") : 1000 * *std::max_element(pos_err.begin(), pos_err.end()))},
           {"start_error_mm", json_number(1000 * mean(start_pos_err))},
           {"failures_over_100_mm", failures}}},
         {"trials_without_selfloc_failure", trials_ok},
         {"equal_no_selfloc_failure", fix_json(f_eq_ok)},
         {"weighted_no_selfloc_failure", fix_json(f_w_ok)},
         {"sightings",
          {{"total", n_sightings},
           {"seen", n_seen},
           {"usable", n_usable},
           {"missed_fraction", missed_frac},
           {"missed_fully_occluded", miss_full},
           {"missed_partly_occluded", miss_partial},
           {"missed_clear_view", miss_clear},
           {"seen_without_distance", n_no_distance},
           {"partly_occluded_total", partial_total},
           {"partly_occluded_used", seen_partial},
           {"partly_occluded_median_abs_distance_error_mm", json_number(1000 * median(part_d_abs))},
           {"partly_occluded_median_abs_bearing_error_deg", json_number(median(part_b_abs) * 180.0 / kPi)},
           {"multiple_regions", n_multi},
           {"outliers_over_0_5_m", n_outlier},
           {"missed_per_robot", missed_robot}}},
         {"distance_error",
          {{"median_abs_mm", json_number(1000 * median(d_abs))},
           {"median_signed_mm", json_number(1000 * median(d_err))},
           {"median_signed_uncorrected_mm", json_number(1000 * median(c_err))}}},
         {"bearing_error_median_abs_deg", json_number(median(b_abs) * 180.0 / kPi)},
         {"by_distance", bins_json},
         {"robots_vs_error", robots_json},
         {"tracking", track_json},
         {"frames_rendered", renders},
         {"render_ms_per_frame", ms_per_frame},
         {"elapsed_s", elapsed}};
  return j;
}

}  // namespace omniloc::experiments
