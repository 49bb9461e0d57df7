#include "experiments/landmark_maps.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "core/rng.hpp"
#include "experiments/report_format.hpp"
#include "harness/run_directory.hpp"
#include "localization/landmarks/landmark_groups.hpp"
#include "localization/landmarks/landmark_solvers.hpp"

namespace omniloc::experiments {

using landmarks::BearingObs;
using landmarks::Fix;

// --- configuration --------------------------------------------------------------------------------------

LandmarkMapsConfig LandmarkMapsConfig::from_args(const ExperimentArgs& args) {
  LandmarkMapsConfig c;
  c.seed = args.seed;
  c.quick = args.quick;
  c.map_sigma = deg2rad(0.5);
  c.cell_m = args.quick ? 0.2 : 0.1;
  c.map_trials = args.quick ? 10 : 400;
  c.table_trials = args.quick ? 200 : 5000;
  c.sim_waypoints = args.quick ? 4 : 20;
  c.sim_paths = args.quick ? 2 : 20;
  return c;
}

// --- computation ----------------------------------------------------------------------------------------

// Paper 004's field. The paper's frame: origin at the top-left corner of the outer white lines, x along
// the field, y across (downwards in its pictures), 1 cm : 1 px. The paper does not print the field's
// size; its five positions and their descriptions fix it: (300, 315) "on the centre line, towards the
// outside" puts the centre line at x = 300 cm; (140, 200) "right in front of the opponent goal" and
// (460, 200) "right in front of our goal" put both goals' centres at y = 200 cm. So a 600 cm x 400 cm
// field, half the legacy MSL 12 m x 8 m field, whose 2 m goals become 100 cm goals (our assumption).
// The yellow (opponent) goal is at x = 0, the blue (own) goal at x = 600 cm. Landmarks: the four goal
// posts (the goal edges the paper's robot detects), on the goal lines.
// We compute in metres, in the paper's coordinates taken as an ordinary x-y frame: with y pointing down
// that is the mirror image of the field as drawn, which changes no distance and no error.
std::array<Eigen::Vector2d, 4> Field004::posts() const {
  const double a = 0.5 * (width - goal_width), b = 0.5 * (width + goal_width);
  return {Eigen::Vector2d(0.0, a), Eigen::Vector2d(0.0, b), Eigen::Vector2d(length, a), Eigen::Vector2d(length, b)};
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double bearing_to(const Eigen::Vector2d& from, const Eigen::Vector2d& to) { return std::atan2(to.y() - from.y(), to.x() - from.x()); }

// Paper 004, sec. 2.2: D1 = the goal nearer the robot ("fewer pixels from the image centre"), D1_L and
// D1_R its left and right edges, D2_L the nearer edge of the other goal; sec. 2.3 initialises the
// three-point method the same way (P1, P2, P3 = D1_L, D1_R, D2_L). "Left" is the post at the larger
// bearing (anticlockwise), so theta1 = bearing(D1_L) - bearing(D1_R) is in (0, pi) as in the paper's
// figure 7. Chosen from the true geometry: landmark identification is not what is measured here.
std::array<int, 3> select_004(const Field004& f, const Eigen::Vector2d& p) {
  const auto posts = f.posts();
  const double d_yellow = (p - Eigen::Vector2d(0.0, 0.5 * f.width)).norm();
  const double d_blue = (p - Eigen::Vector2d(f.length, 0.5 * f.width)).norm();
  const int d1 = d_yellow <= d_blue ? 0 : 2, d2 = d_yellow <= d_blue ? 2 : 0;
  int left = d1, right = d1 + 1;
  if (angle_diff(bearing_to(p, posts[static_cast<std::size_t>(left)]), bearing_to(p, posts[static_cast<std::size_t>(right)])) < 0.0)
    std::swap(left, right);
  const int d2l = (posts[static_cast<std::size_t>(d2)] - p).norm() <= (posts[static_cast<std::size_t>(d2 + 1)] - p).norm() ? d2 : d2 + 1;
  return {left, right, d2l};
}

// Paper 004's two-circle method with eqs. (7)-(9) read literally: theta_OD from acos, and V_OD2 always
// rotated by the same signed angle (+2 theta_OD as eq. (8) writes, or -2 theta_OD as eq. (9) writes).
// The correct rotation depends on which side of the line O2O1 D1_R lies (landmarks' two_circle_004
// picks it); a fixed sign is right on one side only. A diagnostic, not a library solver.
Fix two_circle_as_printed(std::span<const BearingObs> obs, double sign) {
  if (auto r = landmarks::check_triple(obs); !r.empty()) return landmarks::no_fix(std::move(r));
  const Eigen::Vector2d& D1L = obs[0].landmark;
  const Eigen::Vector2d& D1R = obs[1].landmark;
  const Eigen::Vector2d& D2L = obs[2].landmark;
  const double th1 = wrap_angle(obs[0].bearing - obs[1].bearing);
  const double th2 = wrap_angle(obs[1].bearing - obs[2].bearing);
  if (std::fabs(std::sin(th1)) < landmarks::kSingularTol || std::fabs(std::sin(th2)) < landmarks::kSingularTol)
    return landmarks::no_fix("bearing difference 0 or pi");
  const auto rotate = [](const Eigen::Vector2d& v, double a) {
    return Eigen::Vector2d(std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y());
  };
  const auto centre = [&](const Eigen::Vector2d& V, const Eigen::Vector2d& D, double th) {  // eqs. (2), (4)
    const double a = kPi / 2 - th;
    return Eigen::Vector2d(D + rotate(0.5 * V, a) / std::cos(a));
  };
  const Eigen::Vector2d O1 = centre(D1L - D1R, D1R, th1);
  const Eigen::Vector2d O2 = centre(D1R - D2L, D2L, th2);
  const Eigen::Vector2d V_OD2 = D1R - O2, V_O = O1 - O2;
  if (!(V_O.norm() >= landmarks::kSingularTol * V_OD2.norm())) return landmarks::no_fix("circles coincide");
  const double c = std::clamp(V_OD2.dot(V_O) / (V_OD2.norm() * V_O.norm()), -1.0, 1.0);
  const double th_od = std::acos(c);                                  // eq. (7)
  const Eigen::Vector2d R = rotate(V_OD2, sign * 2.0 * th_od) + O2;  // eq. (8) / (9)
  return landmarks::finish_fix(obs, {}, R, landmarks::landmark_scale(obs));
}
Fix two_circle_eq8(std::span<const BearingObs> obs) { return two_circle_as_printed(obs, +1.0); }
Fix two_circle_eq9(std::span<const BearingObs> obs) { return two_circle_as_printed(obs, -1.0); }

}  // namespace

const std::vector<LandmarkSolver>& landmark_solvers() {
  static const std::vector<LandmarkSolver> list = {
      {"two_circle_004", "two-circle, paper 004 eqs. (1)-(9) (landmarks::two_circle_004)", landmarks::two_circle_004, true},
      {"three_point_004", "three-point, paper 004 eqs. (11)-(22) (landmarks::three_point_004)", landmarks::three_point_004, true},
      {"circle_intersection_003", "circle intersection, paper 003 (landmarks::circle_intersection_003)", landmarks::circle_intersection_003,
       true},
      {"total_like", "ToTal-like closed form (landmarks::total_like)", landmarks::total_like, true},
      {"two_circle_eq8_literal", "two-circle with eq. (8) read literally (+2 theta_OD always); diagnostic", two_circle_eq8, false},
      {"two_circle_eq9_literal", "two-circle with eq. (9) read literally (-2 theta_OD always); diagnostic", two_circle_eq9, false},
  };
  return list;
}

namespace {

constexpr std::size_t kTotal = 3;  // index of total_like, the reference for the agreement check

std::array<BearingObs, 3> observe(const std::array<Eigen::Vector2d, 4>& posts, const std::array<int, 3>& sel, const Eigen::Vector2d& p,
                                  double heading, double sigma, Rng& rng) {
  std::array<BearingObs, 3> obs;
  for (std::size_t k = 0; k < 3; ++k) {
    obs[k].landmark = posts[static_cast<std::size_t>(sel[k])];
    obs[k].bearing = bearing_to(p, obs[k].landmark) - heading + rng.normal(0.0, sigma);
  }
  return obs;
}

// ------------------------------------------------------------------------------------------------
// (a) maps
SolverMaps run_maps(const Field004& f, double cell_m, int trials, double sigma, std::uint64_t seed) {
  const auto& S = landmark_solvers();
  SolverMaps m;
  m.cols = static_cast<int>(std::lround(f.length / cell_m));
  m.rows = static_cast<int>(std::lround(f.width / cell_m));
  m.cell_m = cell_m;
  m.trials = trials;
  m.sigma_deg = rad2deg(sigma);
  const std::size_t cells = static_cast<std::size_t>(m.cols) * static_cast<std::size_t>(m.rows);
  m.mean_cm.assign(S.size(), std::vector<double>(cells, kNaN));
  m.refused.assign(S.size(), std::vector<double>(cells, 0.0));
  m.max_diff_vs_total_cm.assign(S.size(), 0.0);
  m.diff_over_1mm.assign(S.size(), 0);
  const auto posts = f.posts();
  Rng rng = Rng::stream(seed, "landmark_maps/map_004");
  std::vector<Fix> fx(S.size());
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) {
      const Eigen::Vector2d p((c + 0.5) * cell_m, (r + 0.5) * cell_m);
      const auto sel = select_004(f, p);
      std::vector<double> sum(S.size(), 0.0);
      std::vector<int> ok(S.size(), 0);
      for (int t = 0; t < trials; ++t) {
        const double heading = rng.uniform(-kPi, kPi);
        const auto obs = observe(posts, sel, p, heading, sigma, rng);
        for (std::size_t s = 0; s < S.size(); ++s) {
          fx[s] = S[s].fn(obs);
          if (!fx[s].ok) continue;
          sum[s] += 100.0 * std::hypot(fx[s].pose.x - p.x(), fx[s].pose.y - p.y());
          ++ok[s];
        }
        if (fx[kTotal].ok) {
          ++m.compared;
          for (std::size_t s = 0; s < S.size(); ++s) {
            if (!S[s].exact || !fx[s].ok) continue;
            const double d = 100.0 * std::hypot(fx[s].pose.x - fx[kTotal].pose.x, fx[s].pose.y - fx[kTotal].pose.y);
            m.max_diff_vs_total_cm[s] = std::max(m.max_diff_vs_total_cm[s], d);
            if (d > 0.1) ++m.diff_over_1mm[s];
          }
        }
      }
      const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(m.cols) + static_cast<std::size_t>(c);
      for (std::size_t s = 0; s < S.size(); ++s) {
        if (ok[s] > 0) m.mean_cm[s][i] = sum[s] / ok[s];
        m.refused[s][i] = static_cast<double>(trials - ok[s]) / trials;
      }
    }
  return m;
}

// ------------------------------------------------------------------------------------------------
// (b) table 1
}  // namespace

const std::array<Eigen::Vector2d, 5> kTable1True = {Eigen::Vector2d(300, 315), Eigen::Vector2d(140, 200), Eigen::Vector2d(75, 100),
                                                    Eigen::Vector2d(460, 200), Eigen::Vector2d(410, 83)};  // cm

namespace {

Table1 run_table(const Field004& f, int trials, double sigma_deg, std::uint64_t seed) {
  const double sigma = deg2rad(sigma_deg);
  const auto& S = landmark_solvers();
  const auto posts = f.posts();
  Rng rng = Rng::stream(seed, "landmark_maps/table1_004/" + strprintf("%.4f", rad2deg(sigma)));
  Table1 table;
  table.sigma_deg = sigma_deg;
  auto& rows = table.rows;
  rows.assign(kTable1True.size(), std::vector<Table1Cell>(S.size()));
  for (std::size_t k = 0; k < kTable1True.size(); ++k) {
    const Eigen::Vector2d p = kTable1True[k] / 100.0;
    const auto sel = select_004(f, p);
    std::vector<double> sx(S.size(), 0.0), sy(S.size(), 0.0), se(S.size(), 0.0), mx(S.size(), 0.0);
    for (int t = 0; t < trials; ++t) {
      const auto obs = observe(posts, sel, p, rng.uniform(-kPi, kPi), sigma, rng);
      for (std::size_t s = 0; s < S.size(); ++s) {
        const Fix fx = S[s].fn(obs);
        Table1Cell& cell = rows[k][s];
        if (!fx.ok) {
          ++cell.refused;
          continue;
        }
        ++cell.ok;
        sx[s] += 100.0 * fx.pose.x;
        sy[s] += 100.0 * fx.pose.y;
        const double e = 100.0 * std::hypot(fx.pose.x - p.x(), fx.pose.y - p.y());
        se[s] += e;
        mx[s] = std::max(mx[s], e);
      }
    }
    for (std::size_t s = 0; s < S.size(); ++s) {
      Table1Cell& cell = rows[k][s];
      if (cell.ok == 0) continue;
      cell.mean_x = sx[s] / cell.ok;
      cell.mean_y = sy[s] / cell.ok;
      cell.mean_err = se[s] / cell.ok;
      cell.max_err = mx[s];
    }
  }
  return table;
}


// ------------------------------------------------------------------------------------------------
// (c) paper 003's simulation (sec. 3.1). The paper: "4 landmarks at (-40, -40), (-40, 40), (40, -40),
// (40, 40) m; observation distance error 1 m; visible range 8 m". Read literally, the landmarks are 80 m
// apart and at most one is ever within 8 m, so no group of three could form and the method could not
// run at all. Our reading: the coordinates are in decimetres, i.e. landmarks at (+-4, +-4) m, the scale
// of the paper's real test (10 m x 8 m, four cubes, robot starting in the middle); range 8 m and the
// 1 m distance error as printed. Colours as in the real test: two red, one blue, one yellow (red on one
// diagonal), which gives exactly two groups, mirror images of each other (the situation of the paper's
// figure 1). Our choices where the paper is silent: distance error uniform in [-1, 1] m (a bound);
// bearing noise N(0, 1 deg); the robot starts at (0, 0) heading 0 (the global origin, as in the paper)
// and drives straight at 0.1 m per frame through random waypoints in [-3, 3] m x [-3, 3] m; plausible
// region: circle on the diameter from the last estimate to the current waypoint, enlarged by 1 m; group
// matching thresholds 2 m and 45 deg (the 1 m distance errors move |d12| by up to 2 m per frame).
// Optional distractor (ours, to give the voting something to reject): a red object walking at 0.05 m per
// frame through random waypoints in [-5, 5] m x [-5, 5] m, seen like a landmark when within range.
struct SimFrame {
  Pose2 truth;
  Eigen::Vector2d goal;
  std::vector<landmarks::LandmarkSighting> sightings;
};

constexpr int kRed = 0, kBlue = 1, kYellow = 2;

std::vector<SimFrame> make_sim_frames(std::uint64_t seed, int waypoints, bool distractor) {
  const std::array<Eigen::Vector2d, 4> lm = {Eigen::Vector2d(-4, -4), Eigen::Vector2d(-4, 4), Eigen::Vector2d(4, -4), Eigen::Vector2d(4, 4)};
  const std::array<int, 4> colour = {kRed, kBlue, kYellow, kRed};
  const double range = 8.0, dist_err = 1.0, bearing_sigma = deg2rad(1.0), step = 0.1, d_step = 0.05;
  Rng path = Rng::stream(seed, "sim003/path");
  Rng noise = Rng::stream(seed, "sim003/noise");
  Rng dpath = Rng::stream(seed, "sim003/distractor");
  std::vector<Eigen::Vector2d> goals;
  Eigen::Vector2d at(0, 0);
  while (static_cast<int>(goals.size()) < waypoints) {
    const Eigen::Vector2d g(path.uniform(-3, 3), path.uniform(-3, 3));
    if ((g - at).norm() < 1.0) continue;
    goals.push_back(g);
    at = g;
  }
  Eigen::Vector2d dpos(dpath.uniform(-5, 5), dpath.uniform(-5, 5)), dgoal(dpath.uniform(-5, 5), dpath.uniform(-5, 5));
  std::vector<SimFrame> frames;
  Pose2 truth(0, 0, 0);
  const auto shoot = [&](const Eigen::Vector2d& goal) {
    SimFrame fr;
    fr.truth = truth;
    fr.goal = goal;
    std::vector<std::pair<Eigen::Vector2d, int>> objects;
    for (std::size_t i = 0; i < lm.size(); ++i) objects.emplace_back(lm[i], colour[i]);
    if (distractor) objects.emplace_back(dpos, kRed);
    for (const auto& [w, col] : objects) {
      const Eigen::Vector2d rel = truth.inverse_transform(w);
      const double d = rel.norm();
      if (d > range) continue;
      landmarks::LandmarkSighting s;
      s.colour = col;
      s.distance = std::max(0.0, d + noise.uniform(-dist_err, dist_err));
      s.bearing = wrap_angle(std::atan2(rel.y(), rel.x()) + noise.normal(0.0, bearing_sigma));
      fr.sightings.push_back(s);
    }
    // The order blobs are listed in should not favour any group: shuffle.
    for (std::size_t i = fr.sightings.size(); i > 1; --i) std::swap(fr.sightings[i - 1], fr.sightings[noise.uniform_index(i)]);
    frames.push_back(std::move(fr));
    // The distractor walks on.
    if ((dgoal - dpos).norm() <= d_step) dgoal = Eigen::Vector2d(dpath.uniform(-5, 5), dpath.uniform(-5, 5));
    dpos += d_step * (dgoal - dpos).normalized();
  };
  shoot(goals.front());
  for (const Eigen::Vector2d& g : goals) {
    for (;;) {
      const Eigen::Vector2d d = g - truth.translation();
      const double len = d.norm();
      if (len < 1e-9) break;
      const Eigen::Vector2d next = len <= step ? g : Eigen::Vector2d(truth.translation() + step * d / len);
      truth = Pose2(next.x(), next.y(), std::atan2(d.y(), d.x()));
      shoot(g);
    }
  }
  return frames;
}

landmarks::GroupLocalizerParams sim_params(bool voting, bool remember) {
  landmarks::GroupLocalizerParams p;
  p.remember_groups = remember;
  p.match.max_distance_diff = 2.0;
  p.match.max_angle_diff = deg2rad(45.0);
  p.use_voting = voting;
  return p;
}

Sim003Stats run_sim(const std::vector<SimFrame>& frames, bool remember) {
  Sim003Stats st;
  landmarks::GroupLocalizer vote(Pose2(0, 0, 0), sim_params(true, remember)), plain(Pose2(0, 0, 0), sim_params(false, remember));
  for (const SimFrame& fr : frames) {
    const auto region = landmarks::PlausibleRegion::from_path(vote.estimate().translation(), fr.goal, LandmarkMapsResult::kSimRegionMargin);
    const auto rv = vote.update(fr.sightings, region);
    const auto rp = plain.update(fr.sightings, landmarks::PlausibleRegion::everywhere());
    const Eigen::Vector2d t = fr.truth.translation();
    st.err_vote.push_back((rv.estimate.translation() - t).norm());
    st.err_novote.push_back((rp.estimate.translation() - t).norm());
    double worst = kNaN;
    for (const Pose2& q : rv.fixes) {
      const double e = (q.translation() - t).norm();
      st.fix_errors.push_back(e);
      worst = std::isfinite(worst) ? std::max(worst, e) : e;
    }
    st.worst_fix.push_back(worst);
    ++st.frames;
    if (!rv.vote.accepted) ++st.kept;
    if (rv.vote.forced) ++st.forced;
    for (const auto& g : rv.groups) st.new_groups_vote += g.previous < 0;
    for (const auto& g : rp.groups) st.new_groups_novote += g.previous < 0;
  }
  return st;
}

/// One condition of the paper 003 simulation over every path; the same frames (truth, noise,
/// distractor) for both ways of recognising groups.
std::array<Sim003Condition, 2> run_sim_conditions(const LandmarkMapsConfig& cfg, bool distractor) {
  std::array<Sim003Condition, 2> cond;  // [remember_groups]
  for (const bool remember : {false, true})
    cond[remember ? 1 : 0].name = strprintf("%s_%s", distractor ? "distractor" : "paper", remember ? "memory" : "consecutive");
  for (int k = 0; k < cfg.sim_paths; ++k) {
    const auto frames = make_sim_frames(derive_seed(cfg.seed, strprintf("sim003/path%d", k)), cfg.sim_waypoints, distractor);
    for (const bool remember : {false, true}) {
      Sim003Condition& c = cond[remember ? 1 : 0];
      const Sim003Stats st = run_sim(frames, remember);
      Sim003Stats& a = c.all;
      a.err_vote.insert(a.err_vote.end(), st.err_vote.begin(), st.err_vote.end());
      a.err_novote.insert(a.err_novote.end(), st.err_novote.begin(), st.err_novote.end());
      a.fix_errors.insert(a.fix_errors.end(), st.fix_errors.begin(), st.fix_errors.end());
      a.frames += st.frames;
      a.kept += st.kept;
      a.forced += st.forced;
      a.new_groups_vote += st.new_groups_vote;
      a.new_groups_novote += st.new_groups_novote;
      c.paths.push_back(st);
      if (k == 0)
        for (const auto& fr : frames) c.path0_truth.push_back(fr.truth);
    }
  }
  return cond;
}

}  // namespace

LandmarkMapsResult compute_landmark_maps(const LandmarkMapsConfig& cfg) {
  LandmarkMapsResult r;
  r.maps = run_maps(r.field, cfg.cell_m, cfg.map_trials, cfg.map_sigma, cfg.seed);
  for (double sd : cfg.table_sigmas_deg) r.tables.push_back(run_table(r.field, cfg.table_trials, sd, cfg.seed));
  for (const bool distractor : {false, true})
    for (Sim003Condition& c : run_sim_conditions(cfg, distractor)) r.sim.push_back(std::move(c));
  return r;
}

// --- the experiment -------------------------------------------------------------------------------------

int run_landmark_maps(const ExperimentArgs& args, std::ostream& out) {
  const LandmarkMapsConfig cfg = LandmarkMapsConfig::from_args(args);
  harness::RunDirectory dir(args.out_dir);  // refuses an unusable output folder before any work
  const LandmarkMapsResult r = compute_landmark_maps(cfg);
  write_landmark_maps_report(cfg, r, dir, out);
  return 0;
}

}  // namespace omniloc::experiments
