// Rendered-image mode of the paper-001 simulation: the computation. See cooperative_001_rendered.hpp
// and docs/cooperative.md ("Rendered mode").
#include "experiments/cooperative_001_rendered.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <ostream>

#include "core/angles.hpp"
#include "core/rng.hpp"
#include "experiments/report_format.hpp"
#include "harness/cache/cache_dirs.hpp"
#include "harness/camera_perception.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/vision_setup.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/matching.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/render/panoramic_camera.hpp"

namespace omniloc::experiments {

using harness::CameraPerception;
using harness::LocalizerContext;
using harness::VisionConfig;
using harness::make_localizer;

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

// --- result accumulators --------------------------------------------------------------------------------

void CoopFixAcc::add(const BallFix& f, const Eigen::Vector2d& B) {
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

void CoopFixAcc::end_trial() {
  if (trial_n > 0) per_trial.push_back(trial_sum / trial_n);
  trial_sum = 0;
  trial_n = 0;
}

double CoopFixAcc::trial_mean() const { return trial_n ? trial_sum / trial_n : std::nan(""); }

double CoopFixAcc::rms_per_axis() const { return errors.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(errors.size()) / 2.0); }

double CoopSightingStats::missed_fraction() const { return total ? 1.0 - static_cast<double>(usable) / total : 0.0; }

// --- the run --------------------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;

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

/// The robot-side vision: the ball's colour only, no goal edges.
VisionConfig ball_vision(const CoopRenderedConfig& g) {
  VisionConfig vc;
  vc.scan.line_width = g.field.line_width;
  vc.blobs_detect = "on";
  vc.blobs.colours = {kBallOrange};
  vc.blobs.edge_colours.clear();
  vc.blobs.min_area_px = g.min_area_px;
  vc.blob_edge_colours_given = true;  // the ball only: no goal edges
  return vc;
}

/// What every trial shares: the camera rig with its off-line set-up, the robots' true poses, the
/// self-localiser. Renders are timed into the result.
struct RenderedScene {
  const Cooperative001Config& c;
  const CoopRenderedConfig& g;
  const Eigen::Vector2d half;  ///< paper frame -> field frame: p - half
  // Off-line set-up as a team does it (cached in the cache root, core/cache_root.hpp): mirror calibration and colour table
  // for this camera and this field, then the robot-side detectors.
  CameraPerception rig;
  const Clock::time_point setup_done;
  std::vector<Pose2> truth;                  ///< field frame
  std::vector<Eigen::Vector2d> robots_paper; ///< paper frame, for the geometry
  std::unique_ptr<Localizer> loc;            ///< null for NoisyTruth

  RenderedScene(const Cooperative001Config& cfg, std::uint64_t seed)
      : c(cfg), g(*cfg.rendered), half(0.5 * cfg.field_length, 0.5 * cfg.field_width), rig(g.camera, g.field, ball_vision(g), seed), setup_done(Clock::now()) {
    // True poses. Default heading: each robot faces the middle of the ball path, as a robot watching
    // the play would (the paper does not give headings).
    const Eigen::Vector2d mid = 0.5 * (c.ball_start + c.ball_end);
    for (std::size_t i = 0; i < c.robots.size(); ++i) {
      const Eigen::Vector2d p = c.robots[i];
      const double h = g.headings.empty() ? std::atan2(mid.y() - p.y(), mid.x() - p.x()) : g.headings[i];
      truth.emplace_back(p.x() - half.x(), p.y() - half.y(), h);
      robots_paper.push_back(p);
    }
    if (g.pose_source == CoopPoseSource::Matching) {
      LocalizerContext ctx;
      ctx.field = &g.field;
      ctx.seed = derive_seed(seed, "rendered/localizer");
      ctx.cache_dir = harness::build_cache_dir("fieldmaps");
      loc = make_localizer(g.localizer, "/rendered/self_localisation/localizer", ctx);
    }
  }

  /// The world with every robot standing at its true pose and the ball at `ball_paper`.
  sim::WorldState world_at(const Eigen::Vector2d& ball_paper, double t) const {
    sim::WorldState w;
    w.t = t;
    for (std::size_t i = 0; i < truth.size(); ++i) {
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
  }

  Image render(const sim::WorldState& w, std::size_t robot, Rng& rng, CoopRenderedResult& r) {
    const auto r0 = Clock::now();
    Image img = rig.camera().render(w, static_cast<int>(robot), g.camera.initial, rng);
    r.render_ms += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
    ++r.renders;
    return img;
  }
};

/// Robot i self-localises with the localizer on `selfloc_frames` frames, standing still with the
/// ball at the path's start, from a start `start_offset` / `start_heading_offset` off the truth.
Pose2 matching_pose(RenderedScene& s, std::size_t i, Rng& cam_rng, Rng& start_rng, CoopRenderedResult& r) {
  const CoopRenderedConfig& g = s.g;
  const Pose2& truth = s.truth[i];
  const double a = start_rng.uniform(-kPi, kPi);
  const double sign = start_rng.uniform() < 0.5 ? -1.0 : 1.0;
  const Pose2 start(truth.x + g.start_offset * std::cos(a), truth.y + g.start_offset * std::sin(a), truth.theta + sign * g.start_heading_offset);
  r.start_pos_err.push_back(g.start_offset);
  s.loc->reset(start);
  // The robot knows its start is only rough: widen the filter's prior to the start error,
  // otherwise the matching's Kalman filter trusts the wrong start for many frames.
  if (auto* m = dynamic_cast<MatchingLocalizer*>(s.loc.get())) {
    const double sxy = std::max(0.05, g.start_offset), sth = std::max(0.02, g.start_heading_offset);
    m->filter().reset(start, Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal());
  }
  Estimate e;
  for (int f = 0; f < g.selfloc_frames; ++f) {
    const double tf = -s.c.step_time * (g.selfloc_frames - f);  // before the ball starts rolling at t = 0
    const Image img = s.render(s.world_at(s.c.ball_start, tf), i, cam_rng, r);
    Odometry odo;
    odo.t = tf;  // standing still: zero motion
    e = s.loc->update(s.rig.detector().observe(img, tf), odo, std::nullopt);
  }
  return e.pose;
}

/// 1. Self-localisation of every robot (or the noisy truth); its errors into `r`.
std::vector<Pose2> self_localise(RenderedScene& s, int t, std::vector<Rng>& cam_rng, Rng& start_rng, CoopRenderedResult& r) {
  const CoopRenderedConfig& g = s.g;
  std::vector<Pose2> est(s.truth.size());
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Pose2& truth = s.truth[i];
    if (g.pose_source == CoopPoseSource::NoisyTruth) {
      est[i] = Pose2(truth.x + g.pose_sigma * start_rng.normal(), truth.y + g.pose_sigma * start_rng.normal(), truth.theta);
      r.start_pos_err.push_back((est[i].translation() - truth.translation()).norm());
    } else {
      est[i] = matching_pose(s, i, cam_rng[i], start_rng, r);
    }
    const double pe = (est[i].translation() - truth.translation()).norm();
    r.pos_err.push_back(pe);
    r.pos_err_robot[i].push_back(pe);
    if (pe > CoopRenderedResult::kSelflocFail)
      r.failures.push_back(strprintf("trial %d robot %d: %.0f mm, %.1f deg", t + 1, static_cast<int>(i) + 1, 1000 * pe,
                                     std::abs(wrap_angle(est[i].theta - truth.theta)) * 180.0 / kPi));
    r.head_err.push_back(std::abs(wrap_angle(est[i].theta - truth.theta)));
  }
  return est;
}

/// Scores robot i's sighting of the ball at B (paper frame) against the truth; true when usable.
bool score_sighting(const RenderedScene& s, std::size_t i, const Eigen::Vector2d& B, const RenderedBallSighting& sg, CoopSightingStats& st) {
  const Eigen::Vector2d rel = s.truth[i].inverse_transform(B - s.half);
  const double D = rel.norm(), beta = std::atan2(rel.y(), rel.x());
  const int occ = occlusion_class(s.robots_paper, i, B, s.g.robot_radius, s.g.ball_radius);
  const int bin = std::min(CoopSightingStats::kBins - 1, static_cast<int>(D));
  const auto bu = static_cast<std::size_t>(bin);
  ++st.total;
  ++st.bin_total[bu];
  if (occ == 1) ++st.partly_occluded_total;
  if (sg.seen) ++st.seen;
  if (sg.regions > 1) ++st.multiple_regions;
  if (sg.seen && !sg.has_distance) ++st.no_distance;
  if (!sg.seen || !sg.has_distance) {
    ++st.bin_missed[bu];
    ++st.missed_per_robot[i];
    if (!sg.seen) (occ == 2 ? st.missed_fully_occluded : occ == 1 ? st.missed_partly_occluded : st.missed_clear)++;
    return false;
  }
  if (occ == 1) ++st.partly_occluded_used;
  ++st.usable;
  const double de = sg.distance - D, be = wrap_angle(sg.bearing - beta);
  if ((sg.position() - rel).norm() > 0.5) ++st.outliers;  // something else orange, or a badly cut ball
  st.d_err.push_back(de);
  st.d_abs.push_back(std::abs(de));
  st.c_err.push_back(sg.contact_distance - D);
  st.b_abs.push_back(std::abs(be));
  if (occ == 1) {
    st.part_d_abs.push_back(std::abs(de));
    st.part_b_abs.push_back(std::abs(be));
  }
  st.bin_d_abs[bu].push_back(std::abs(de));
  st.bin_d_err[bu].push_back(de);
  st.bin_b_abs[bu].push_back(std::abs(be));
  return true;
}

/// Lines L_i per step and robot (paper frame), from the estimated and (diagnostic) the true poses.
struct TrialLines {
  std::vector<std::vector<std::optional<BallLine>>> est, truth;  ///< [step][robot]
};

/// 2. The ball rolls; every robot renders, detects and reports.
TrialLines observe_path(RenderedScene& s, const std::vector<Pose2>& est, std::vector<Rng>& cam_rng, CoopRenderedResult& r) {
  const Cooperative001Config& c = s.c;
  const CoopRenderedConfig& g = s.g;
  const int K = c.path_positions();
  const std::size_t nr = s.truth.size();
  TrialLines L;
  L.est.assign(static_cast<std::size_t>(K), std::vector<std::optional<BallLine>>(nr));
  L.truth = L.est;
  for (int k = 0; k < K; ++k) {
    const double tk = k * c.step_time;
    const Eigen::Vector2d B = c.ball_at(tk);
    const sim::WorldState w = s.world_at(B, tk);
    for (std::size_t i = 0; i < nr; ++i) {
      const Image img = s.render(w, i, cam_rng[i], r);
      const RenderedBallSighting sg = ball_sighting_from_blobs(s.rig.blob_detector()->detect(img), g.min_area_px, g.camera.mount_height, g.ball_radius);
      if (!score_sighting(s, i, B, sg, r.sightings)) continue;
      BallLine l;
      l.stamp = tk;
      l.robot = est[i].translation() + s.half;  // back to the paper frame
      l.ball_estimate = est[i].transform(sg.position()) + s.half;
      L.est[static_cast<std::size_t>(k)][i] = l;
      BallLine lt = l;
      lt.robot = s.truth[i].translation() + s.half;
      lt.ball_estimate = s.truth[i].transform(sg.position()) + s.half;
      L.truth[static_cast<std::size_t>(k)][i] = lt;
      r.own_err.push_back((l.ball_estimate - B).norm());
    }
  }
  return L;
}

/// 3. Fixes: all robots (estimated and, as a diagnostic, true poses), and every subset.
void fuse_trial(const Cooperative001Config& c, const TrialLines& L, bool trial_ok, CoopRenderedResult& r) {
  const HoughBallConfig eq_cfg = coop_hough_config(BallWeighting::Equal), w_cfg = coop_hough_config(BallWeighting::InverseDistance);
  const int K = c.path_positions();
  const std::size_t nr = c.robots.size();
  r.seq_w.emplace_back(static_cast<std::size_t>(K));
  r.seq_eq.emplace_back(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const Eigen::Vector2d B = c.ball_at(k * c.step_time);
    std::vector<BallLine> all, all_true;
    for (std::size_t i = 0; i < nr; ++i)
      if (L.est[ku][i]) {
        all.push_back(*L.est[ku][i]);
        all_true.push_back(*L.truth[ku][i]);
      }
    const BallFix fe = hough_ball_fix(all, eq_cfg), fw = hough_ball_fix(all, w_cfg);
    r.f_eq.add(fe, B);
    r.f_w.add(fw, B);
    r.f_eq_true.add(hough_ball_fix(all_true, eq_cfg), B);
    r.f_w_true.add(hough_ball_fix(all_true, w_cfg), B);
    if (trial_ok) {
      r.f_eq_ok.add(fe, B);
      r.f_w_ok.add(fw, B);
    }
    if (fw.status != BallFix::Status::NoObservation) r.seq_w.back()[ku] = fw.position;
    if (fe.status != BallFix::Status::NoObservation) r.seq_eq.back()[ku] = fe.position;
    for (unsigned mask = 1; mask < (1u << nr); ++mask) {
      std::vector<BallLine> sub;
      std::size_t size = 0;
      for (std::size_t i = 0; i < nr; ++i)
        if (mask & (1u << i)) {
          ++size;
          if (L.est[ku][i]) sub.push_back(*L.est[ku][i]);
        }
      ++r.sub_steps[size];
      const BallFix se = hough_ball_fix(sub, eq_cfg), sw = hough_ball_fix(sub, w_cfg);
      if (sw.status == BallFix::Status::NoObservation) {
        ++r.sub_nofix[size];
        continue;
      }
      r.sub_eq_sum[size] += (se.position - B).norm();
      const double ew = (sw.position - B).norm();
      r.sub_w_sum[size] += ew;
      r.sub_w_err[size].push_back(ew);
      ++r.sub_n[size];
    }
  }
}

/// 4. Trackers on the rendered fixes (no rendering; obs_sigma = the input's measured per-axis RMS).
void track_fixes(const Cooperative001Config& c, std::uint64_t seed, CoopRenderedResult& r) {
  const auto& trackers = coop_trackers();
  r.tracking_inputs = {"1/L fix", "equal fix"};
  r.tracking_obs_sigma = {r.f_w.rms_per_axis(), r.f_eq.rms_per_axis()};
  const std::vector<const std::vector<CoopFixSequence>*> seqs = {&r.seq_w, &r.seq_eq};
  r.track_mean.assign(seqs.size(), std::vector<double>(trackers.size(), std::nan("")));
  if (c.rendered->tracking_repeats <= 0) return;
  for (std::size_t in = 0; in < seqs.size(); ++in)
    for (std::size_t tk = 0; tk < trackers.size(); ++tk) {
      double sum = 0, n = 0;
      const int reps = trackers[tk] == "kf" ? 1 : c.rendered->tracking_repeats;  // the Kalman filter draws nothing
      for (std::size_t tr = 0; tr < seqs[in]->size(); ++tr) {
        const CoopFixSequence& z = (*seqs[in])[tr];
        const std::optional<Eigen::Vector2d> first = first_fix(z);
        if (!first) continue;
        for (int rep = 0; rep < reps; ++rep) {  // the trackers as in the direct-noise tracking table
          Rng frng = cooperative_trial_rng(seed, "rendered/tracking/" + trackers[tk] + "/" + r.tracking_inputs[in], static_cast<int>(tr) * 10007 + rep);
          for (double e : coop_tracker_errors(c, trackers[tk], r.tracking_obs_sigma[in], *first, z, frng)) {
            sum += e;
            n += 1;
          }
        }
      }
      r.track_mean[in][tk] = n > 0 ? sum / n : std::nan("");
    }
}

}  // namespace

CoopRenderedResult compute_cooperative_rendered(const Cooperative001Config& c, int trials, std::uint64_t seed, std::ostream* progress) {
  const auto t_start = Clock::now();
  const std::size_t nr = c.robots.size();
  RenderedScene s(c, seed);
  CoopRenderedResult r;
  r.trials = trials;
  r.path_positions = c.path_positions();
  r.setup_s = std::chrono::duration<double>(s.setup_done - t_start).count();
  r.pos_err_robot.resize(nr);
  r.sightings.missed_per_robot.assign(nr, 0);
  for (auto* v : {&r.sub_eq_sum, &r.sub_w_sum, &r.sub_n, &r.sub_nofix, &r.sub_steps}) v->assign(nr + 1, 0.0);
  r.sub_w_err.resize(nr + 1);
  for (int t = 0; t < trials; ++t) {
    // One camera stream per robot and trial (vibration, pixel noise), used for its self-localisation
    // frames and then its path frames.
    std::vector<Rng> cam_rng;
    for (std::size_t i = 0; i < nr; ++i) cam_rng.push_back(cooperative_trial_rng(seed, "rendered/camera/" + std::to_string(i), t));
    Rng start_rng = cooperative_trial_rng(seed, "rendered/start", t);
    const std::vector<Pose2> est = self_localise(s, t, cam_rng, start_rng, r);
    bool trial_ok = true;
    for (std::size_t i = 0; i < nr; ++i)
      trial_ok = trial_ok && (est[i].translation() - s.truth[i].translation()).norm() <= CoopRenderedResult::kSelflocFail;
    r.trials_ok += trial_ok;
    fuse_trial(c, observe_path(s, est, cam_rng, r), trial_ok, r);
    const double m_eq = r.f_eq.trial_mean(), m_w = r.f_w.trial_mean();
    if (std::isfinite(m_eq) && std::isfinite(m_w)) {
      r.diff_per_trial.push_back(m_w - m_eq);
      if (trial_ok) r.diff_ok.push_back(m_w - m_eq);
    }
    for (CoopFixAcc* a : {&r.f_eq, &r.f_w, &r.f_eq_true, &r.f_w_true, &r.f_eq_ok, &r.f_w_ok}) a->end_trial();
    if (progress)
      *progress << strprintf("rendered mode: trial %d/%d done, %.0f s\n", t + 1, trials, std::chrono::duration<double>(Clock::now() - t_start).count())
                << std::flush;
  }
  track_fixes(c, seed, r);
  r.elapsed_s = std::chrono::duration<double>(Clock::now() - t_start).count();
  return r;
}

}  // namespace omniloc::experiments
