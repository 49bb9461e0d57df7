#include "experiments/landmark_maps.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "core/atomic_file.hpp"
#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "experiments/text_format.hpp"
#include "harness/field_picture.hpp"
#include "harness/plot.hpp"
#include "harness/run_directory.hpp"
#include "localization/landmarks/landmark_groups.hpp"
#include "localization/landmarks/landmark_solvers.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using harness::Series;
using harness::heat_map;
using harness::line_plot;
using harness::png_bytes;

namespace {

using landmarks::BearingObs;
using landmarks::Fix;


constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ------------------------------------------------------------------------------------------------
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
struct Field004 {
  double length = 6.0;      // metres
  double width = 4.0;       // metres
  double goal_width = 1.0;  // metres, between the posts
  std::array<Eigen::Vector2d, 4> posts() const {
    const double a = 0.5 * (width - goal_width), b = 0.5 * (width + goal_width);
    return {Eigen::Vector2d(0.0, a), Eigen::Vector2d(0.0, b), Eigen::Vector2d(length, a), Eigen::Vector2d(length, b)};
  }
};

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

struct Solver {
  const char* name;
  const char* label;
  Fix (*fn)(std::span<const BearingObs>);
  bool exact;  // a library solver (exact to rounding off its singular set)
};

const std::vector<Solver>& solvers() {
  static const std::vector<Solver> list = {
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

double quantile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}

// ------------------------------------------------------------------------------------------------
// (a) maps
struct MapResult {
  int cols = 0, rows = 0;
  double cell_m = 0.0;
  int trials = 0;
  double sigma_deg = 0.0;
  std::vector<std::vector<double>> mean_cm;      // [solver][cell], NaN when every trial was refused
  std::vector<std::vector<double>> refused;      // [solver][cell], fraction of trials
  std::vector<double> max_diff_vs_total_cm;      // [solver], exact solvers: max |fix - total_like fix|
  std::vector<long> diff_over_1mm;               // [solver], trials where that difference exceeds 1 mm
  long compared = 0;
};

MapResult run_maps(const Field004& f, double cell_m, int trials, double sigma, std::uint64_t seed) {
  const auto& S = solvers();
  MapResult m;
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
const std::array<Eigen::Vector2d, 5> kTable1True = {Eigen::Vector2d(300, 315), Eigen::Vector2d(140, 200), Eigen::Vector2d(75, 100),
                                                    Eigen::Vector2d(460, 200), Eigen::Vector2d(410, 83)};  // cm

struct TableCell {
  double mean_x = kNaN, mean_y = kNaN;  // cm, mean of the accepted estimates
  double mean_err = kNaN;               // cm, mean of |estimate - truth|
  double max_err = kNaN;                // cm
  int ok = 0, refused = 0;
};

std::vector<std::vector<TableCell>> run_table(const Field004& f, int trials, double sigma, std::uint64_t seed) {
  const auto& S = solvers();
  const auto posts = f.posts();
  Rng rng = Rng::stream(seed, "landmark_maps/table1_004/" + strprintf("%.4f", rad2deg(sigma)));
  std::vector<std::vector<TableCell>> rows(kTable1True.size(), std::vector<TableCell>(S.size()));
  for (std::size_t k = 0; k < kTable1True.size(); ++k) {
    const Eigen::Vector2d p = kTable1True[k] / 100.0;
    const auto sel = select_004(f, p);
    std::vector<double> sx(S.size(), 0.0), sy(S.size(), 0.0), se(S.size(), 0.0), mx(S.size(), 0.0);
    for (int t = 0; t < trials; ++t) {
      const auto obs = observe(posts, sel, p, rng.uniform(-kPi, kPi), sigma, rng);
      for (std::size_t s = 0; s < S.size(); ++s) {
        const Fix fx = S[s].fn(obs);
        TableCell& cell = rows[k][s];
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
      TableCell& cell = rows[k][s];
      if (cell.ok == 0) continue;
      cell.mean_x = sx[s] / cell.ok;
      cell.mean_y = sy[s] / cell.ok;
      cell.mean_err = se[s] / cell.ok;
      cell.max_err = mx[s];
    }
  }
  return rows;
}

// Published table: results/reference/papers.json, "004_table1_cm" (the one place published numbers live).
struct Published {
  bool found = false;
  std::string note;
  std::vector<std::array<double, 8>> rows;  // true x, y, two-circle x, y, err, three-point x, y, err
};

Published read_published() {
  Published p;
  const std::string path = std::string(OMNILOC_SOURCE_DIR) + "/results/reference/papers.json";
  try {
    const Json j = Json::parse(read_file(path));
    if (!j.contains("004_table1_cm")) {
      p.note = path + " has no \"004_table1_cm\"";
      return p;
    }
    for (const auto& r : j.at("004_table1_cm").at("rows")) {
      std::array<double, 8> a{};
      for (std::size_t i = 0; i < 8; ++i) a[i] = r.at(i).get<double>();
      p.rows.push_back(a);
    }
    p.found = p.rows.size() == kTable1True.size();
    if (!p.found) p.note = "004_table1_cm does not have 5 rows";
  } catch (const std::exception& e) {
    p.note = std::string("cannot read published numbers: ") + e.what();
  }
  return p;
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

struct SimStats {
  std::vector<double> err_vote, err_novote, worst_fix;  // per frame, metres (worst_fix NaN without fixes)
  std::vector<double> fix_errors;                       // every group fix of the voting run, metres
  int frames = 0, kept = 0, forced = 0, new_groups_vote = 0, new_groups_novote = 0;
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
constexpr double kSimRegionMargin = 1.0;  // metres

SimStats run_sim(const std::vector<SimFrame>& frames, bool remember) {
  SimStats st;
  landmarks::GroupLocalizer vote(Pose2(0, 0, 0), sim_params(true, remember)), plain(Pose2(0, 0, 0), sim_params(false, remember));
  for (const SimFrame& fr : frames) {
    const auto region = landmarks::PlausibleRegion::from_path(vote.estimate().translation(), fr.goal, kSimRegionMargin);
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

double mean_of(const std::vector<double>& v) {
  double s = 0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n ? s / n : kNaN;
}
double max_of(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x)) m = std::isfinite(m) ? std::max(m, x) : x;
  return m;
}

Json sim_summary(const SimStats& s) {
  return Json{{"frames", s.frames},
              {"group_fixes", s.fix_errors.size()},
              {"fixes_mean_m", mean_of(s.fix_errors)},
              {"fixes_max_m", max_of(s.fix_errors)},
              {"fixes_over_1m", std::count_if(s.fix_errors.begin(), s.fix_errors.end(), [](double e) { return e > 1.0; })},
              {"no_voting_mean_m", mean_of(s.err_novote)},
              {"no_voting_max_m", max_of(s.err_novote)},
              {"voting_mean_m", mean_of(s.err_vote)},
              {"voting_max_m", max_of(s.err_vote)},
              {"voting_frames_kept_last", s.kept},
              {"voting_forced_accepts", s.forced},
              {"new_groups_voting_run", s.new_groups_vote},
              {"new_groups_no_voting_run", s.new_groups_novote}};
}

Json posts_cm_json(const Field004& f) {
  Json a = Json::array();
  for (const auto& p : f.posts()) a.push_back({100 * p.x(), 100 * p.y()});
  return a;
}

Json num_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

}  // namespace

// ==================================================================================================
int run_landmark_maps(const ExperimentArgs& args, std::ostream& out) {
  const Field004 field;
  const auto& S = solvers();
  const double sigma_map = deg2rad(0.5);
  const double cell_m = args.quick ? 0.2 : 0.1;
  const int map_trials = args.quick ? 10 : 400;
  const int table_trials = args.quick ? 200 : 5000;
  const std::vector<double> table_sigmas_deg = {0.5, 2.0};
  const int sim_waypoints = args.quick ? 4 : 20;
  const int sim_paths = args.quick ? 2 : 20;
  const double cap_cm = 30.0;
  RunDirectory dir(args.out_dir);

  const auto posts = field.posts();
  out << "landmark_maps (seed " << args.seed << (args.quick ? ", quick" : "") << ")\n";
  out << strprintf("Paper 004 field, paper's frame (origin at a line corner, cm): %.0f x %.0f cm; yellow goal posts (%.0f,%.0f) (%.0f,%.0f), "
             "blue goal posts (%.0f,%.0f) (%.0f,%.0f)\n",
             100 * field.length, 100 * field.width, 100 * posts[0].x(), 100 * posts[0].y(), 100 * posts[1].x(), 100 * posts[1].y(),
             100 * posts[2].x(), 100 * posts[2].y(), 100 * posts[3].x(), 100 * posts[3].y());

  // ---- (a) maps
  const MapResult m = run_maps(field, cell_m, map_trials, sigma_map, args.seed);
  out << strprintf("\n(a) Mean position error maps: %d x %d cells of %.0f cm, %d trials per cell, bearing noise N(0, %.1f deg), random heading\n",
             m.cols, m.rows, 100 * cell_m, map_trials, m.sigma_deg);
  out << "solver                     | field mean cm | median cm | p95 cm | worst cell cm | cells > " << cap_cm
      << " cm | trials refused | max |fix - total_like| cm\n";
  Json maps_json = Json::array();
  std::string csv = "x_cm,y_cm";
  for (const auto& s : S) csv += std::string(",") + s.name + "_mean_err_cm," + s.name + "_refused_frac";
  csv += "\n";
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(m.cols) + static_cast<std::size_t>(c);
      csv += strprintf("%.1f,%.1f", 100 * (c + 0.5) * cell_m, 100 * (r + 0.5) * cell_m);
      for (std::size_t s = 0; s < S.size(); ++s)
        csv += std::isfinite(m.mean_cm[s][i]) ? strprintf(",%.4f,%.4f", m.mean_cm[s][i], m.refused[s][i]) : strprintf(",nan,%.4f", m.refused[s][i]);
      csv += "\n";
    }
  for (std::size_t s = 0; s < S.size(); ++s) {
    const auto& v = m.mean_cm[s];
    const double over = static_cast<double>(std::count_if(v.begin(), v.end(), [&](double x) { return !std::isfinite(x) || x > cap_cm; })) /
                        static_cast<double>(v.size());
    double refused = 0;
    for (double x : m.refused[s]) refused += x;
    refused /= static_cast<double>(m.refused[s].size());
    const double fm = mean_of(v), med = quantile(v, 0.5), p95 = quantile(v, 0.95), worst = max_of(v);
    out << strprintf("%-26s | %13.2f | %9.2f | %6.2f | %13.1f | %10.2f %% | %12.4f %% | ", S[s].name, fm, med, p95, worst, 100 * over, 100 * refused)
        << (S[s].exact ? strprintf("%.2e", m.max_diff_vs_total_cm[s]) : std::string("(diagnostic)")) << "\n";
    maps_json.push_back({{"solver", S[s].name},
                         {"label", S[s].label},
                         {"field_mean_cm", fm},
                         {"median_cell_cm", med},
                         {"p95_cell_cm", p95},
                         {"worst_cell_cm", worst},
                         {"cells_over_cap_frac", over},
                         {"trials_refused_frac", refused},
                         {"max_diff_vs_total_like_cm", S[s].exact ? Json(m.max_diff_vs_total_cm[s]) : Json(nullptr)},
                         {"trials_diff_over_1mm", S[s].exact ? Json(m.diff_over_1mm[s]) : Json(nullptr)},
                         {"png", std::string("map_") + S[s].name + ".png"}});
    std::vector<double> capped(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) capped[i] = std::isfinite(v[i]) ? std::min(v[i], cap_cm) : kNaN;
    const int cell_px = std::max(1, static_cast<int>(std::lround(600.0 / m.cols)));
    dir.write(std::string("map_") + S[s].name + ".png",
              png_bytes(heat_map(capped, m.cols, m.rows, 0.0, 100 * field.length, 0.0, 100 * field.width,
                                 strprintf("%s: mean error cm (0.5 deg, capped %.0f)", S[s].name, cap_cm), "x cm (paper 004 frame)", "y cm",
                                 cell_px)));
  }
  out << strprintf("(the four exact solvers compared with total_like on %ld trials; diagnostics: eqs. (8)/(9) of paper 004 with a fixed "
             "rotation sign)\n",
             m.compared);
  dir.write("maps_004.csv", csv);

  // ---- (b) table 1
  const Published pub = read_published();
  if (!pub.found) out << "(published numbers unavailable: " << pub.note << ")\n";
  Json table_json = Json::array();
  std::string md = "# Paper 004, table 1, reproduced (omniloc experiment landmark_maps)\n\n";
  md += strprintf("Field %.0f x %.0f cm (paper 004 frame, origin at a line corner), landmarks = the four goal posts; %d trials per position, "
            "random heading, seed %llu.\n",
            100 * field.length, 100 * field.width, table_trials, static_cast<unsigned long long>(args.seed));
  md += "Ours: mean of the estimates (cm) and mean error (cm) under Gaussian bearing noise. Published: paper 004's single real-robot "
        "estimate and its error (from results/reference/papers.json).\n";
  const std::size_t TC = 0, TP = 1, E8 = 4, E9 = 5;
  for (double sd : table_sigmas_deg) {
    const auto rows = run_table(field, table_trials, deg2rad(sd), args.seed);
    const std::string head =
        "| true (cm) | two-circle mean (cm) | err | three-point mean (cm) | err | published two-circle | err | published three-point | err "
        "| eq. (8) literal err | eq. (9) literal err |\n";
    const std::string rule = "|---|---|---|---|---|---|---|---|---|---|---|\n";
    out << strprintf("\n(b) Paper 004 table 1, bearing noise N(0, %.1f deg), %d trials per position (ours: mean estimate, mean error, cm)\n", sd,
               table_trials)
        << head << rule;
    md += strprintf("\n## Bearing noise N(0, %.1f deg)\n\n", sd) + head + rule;
    Json jrows = Json::array();
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& tc = rows[k][TC];
      const auto& tp = rows[k][TP];
      std::string line = strprintf("| (%.0f, %.0f) | (%.1f, %.1f) | %.2f | (%.1f, %.1f) | %.2f | ", kTable1True[k].x(), kTable1True[k].y(), tc.mean_x,
                             tc.mean_y, tc.mean_err, tp.mean_x, tp.mean_y, tp.mean_err);
      if (pub.found) {
        const auto& p = pub.rows[k];
        line += strprintf("(%.0f, %.0f) | %.3f | (%.0f, %.0f) | %.3f | ", p[2], p[3], p[4], p[5], p[6], p[7]);
      } else {
        line += "- | - | - | - | ";
      }
      line += strprintf("%.1f | %.1f |\n", rows[k][E8].mean_err, rows[k][E9].mean_err);
      out << line;
      md += line;
      Json per = Json::object();
      for (std::size_t s = 0; s < S.size(); ++s) {
        const auto& c = rows[k][s];
        per[S[s].name] = {{"mean_x_cm", num_or_null(c.mean_x)}, {"mean_y_cm", num_or_null(c.mean_y)}, {"mean_err_cm", num_or_null(c.mean_err)},
                          {"max_err_cm", num_or_null(c.max_err)}, {"ok", c.ok},
                          {"refused", c.refused}};
      }
      Json row{{"true_cm", {kTable1True[k].x(), kTable1True[k].y()}}, {"ours", per}};
      if (pub.found)
        row["published"] = {{"two_circle", {pub.rows[k][2], pub.rows[k][3], pub.rows[k][4]}},
                            {"three_point", {pub.rows[k][5], pub.rows[k][6], pub.rows[k][7]}}};
      jrows.push_back(row);
    }
    // Trend check: near the edge ((75, 100) and (410, 83)) against the three central positions.
    const auto ratio = [&](std::size_t s) {
      const double edge = 0.5 * (rows[2][s].mean_err + rows[4][s].mean_err);
      const double centre = (rows[0][s].mean_err + rows[1][s].mean_err + rows[3][s].mean_err) / 3.0;
      return edge / centre;
    };
    const std::string trend = strprintf("edge/centre mean-error ratio: two-circle %.2f, three-point %.2f (published: two-circle %.2f, three-point %.2f); "
                                  "max |two-circle - three-point| mean error over the rows %.2e cm",
                                  ratio(TC), ratio(TP),
                                  pub.found ? 0.5 * (pub.rows[2][4] + pub.rows[4][4]) / ((pub.rows[0][4] + pub.rows[1][4] + pub.rows[3][4]) / 3) : kNaN,
                                  pub.found ? 0.5 * (pub.rows[2][7] + pub.rows[4][7]) / ((pub.rows[0][7] + pub.rows[1][7] + pub.rows[3][7]) / 3) : kNaN,
                                  [&] {
                                    double d = 0;
                                    for (const auto& r : rows) d = std::max(d, std::fabs(r[TC].mean_err - r[TP].mean_err));
                                    return d;
                                  }());
    out << trend << "\n";
    md += "\n" + trend + ".\n";
    // The trend as numbers too, for the report's scorecard (scripts/paper_claims.py).
    table_json.push_back({{"bearing_sigma_deg", sd}, {"trials", table_trials}, {"rows", jrows}, {"trend", trend},
                          {"edge_centre_ratio", {{"two_circle", num_or_null(ratio(TC))}, {"three_point", num_or_null(ratio(TP))}}}});
  }
  dir.write("table1_004.json", Json{{"seed", args.seed},
                                    {"field_cm", {100 * field.length, 100 * field.width}},
                                    {"goal_width_cm", 100 * field.goal_width},
                                    {"posts_cm", posts_cm_json(field)},
                                    {"published_source", pub.found ? "results/reference/papers.json#004_table1_cm" : pub.note},
                                    {"tables", table_json}}
                                   .dump(1) +
                                   "\n");
  dir.write("table1_004.md", md);

  // ---- (c) paper 003's simulation
  out << "\n(c) Paper 003 simulation: landmarks (+-4, +-4) m (the paper's (+-40, +-40) read as decimetres), range 8 m, distance error "
         "U(-1, 1) m, bearing noise N(0, 1 deg); "
      << sim_paths << " random paths of " << sim_waypoints << " waypoints (path 0 plotted)\n";
  out << "condition              | frames | group fixes: mean m   max m  (>1 m) | no voting: mean m  max m | voting: mean m  max m | kept last | "
         "forced | new groups\n";
  Json sim_json{{"landmarks_m", {{-4, -4, "red"}, {-4, 4, "blue"}, {4, -4, "yellow"}, {4, 4, "red"}}},
                {"range_m", 8.0},
                {"distance_error", "uniform [-1, 1] m"},
                {"bearing_noise_deg", 1.0},
                {"match", {{"max_distance_diff_m", 2.0}, {"max_angle_diff_deg", 45.0}}},
                {"voting", {{"position_tol_m", 0.5}, {"heading_tol_deg", 10.0}, {"deadlock_limit", 3}}},
                {"plausible_margin_m", kSimRegionMargin},
                {"paths", sim_paths},
                {"waypoints_per_path", sim_waypoints}};
  for (const bool distractor : {false, true}) {
    std::array<SimStats, 2> all;  // [remember_groups]
    std::array<Json, 2> per_path = {Json::array(), Json::array()};
    for (int k = 0; k < sim_paths; ++k) {
      // The same frames (truth, noise, distractor) for both ways of recognising groups.
      const auto frames = make_sim_frames(derive_seed(args.seed, strprintf("sim003/path%d", k)), sim_waypoints, distractor);
      for (const bool remember : {false, true}) {
        const std::string cname = strprintf("%s_%s", distractor ? "distractor" : "paper", remember ? "memory" : "consecutive");
        const SimStats st = run_sim(frames, remember);
        SimStats& a = all[remember ? 1 : 0];
        per_path[remember ? 1 : 0].push_back(sim_summary(st));
        a.err_vote.insert(a.err_vote.end(), st.err_vote.begin(), st.err_vote.end());
        a.err_novote.insert(a.err_novote.end(), st.err_novote.begin(), st.err_novote.end());
        a.fix_errors.insert(a.fix_errors.end(), st.fix_errors.begin(), st.fix_errors.end());
        a.frames += st.frames;
        a.kept += st.kept;
        a.forced += st.forced;
        a.new_groups_vote += st.new_groups_vote;
        a.new_groups_novote += st.new_groups_novote;
        if (k != 0) continue;
        Series sv{"voting", {}, st.err_vote}, sn{"no voting", {}, st.err_novote}, sw{"worst group fix", {}, {}};
        for (std::size_t i = 0; i < st.err_vote.size(); ++i) {
          sv.x.push_back(static_cast<double>(i));
          sn.x.push_back(static_cast<double>(i));
          if (std::isfinite(st.worst_fix[i])) {
            sw.x.push_back(static_cast<double>(i));
            sw.y.push_back(st.worst_fix[i]);
          }
        }
        dir.write("sim_003_" + cname + ".png",
                  png_bytes(line_plot({sw, sn, sv}, "Paper 003 simulation, " + cname + ", path 0: position error", "frame", "error m")));
        Json series{{"truth", Json::array()}, {"err_vote_m", st.err_vote}, {"err_novote_m", st.err_novote}, {"worst_fix_m", Json::array()}};
        for (const auto& fr : frames) series["truth"].push_back({fr.truth.x, fr.truth.y, fr.truth.theta});
        for (double w : st.worst_fix) series["worst_fix_m"].push_back(num_or_null(w));
        sim_json[cname + "_path0"] = series;
      }
    }
    for (const bool remember : {false, true}) {
      const std::string cname = strprintf("%s_%s", distractor ? "distractor" : "paper", remember ? "memory" : "consecutive");
      const SimStats& a = all[remember ? 1 : 0];
      const Json sum = sim_summary(a);
      sim_json[cname] = {{"all_paths", sum}, {"per_path", per_path[remember ? 1 : 0]}};
      out << strprintf("%-22s | %6d | %10.3f %7.3f (%5ld) | %9.3f %6.3f | %7.3f %6.3f | %9d | %6d | %d\n", cname.c_str(), a.frames,
                 mean_of(a.fix_errors), max_of(a.fix_errors), static_cast<long>(sum["fixes_over_1m"].get<long>()), mean_of(a.err_novote),
                 max_of(a.err_novote), mean_of(a.err_vote), max_of(a.err_vote), a.kept, a.forced, a.new_groups_vote);
    }
  }
  dir.write("sim_003.json", sim_json.dump() + "\n");  // per-frame series: compact

  Json top{{"seed", args.seed},
           {"quick", args.quick},
           {"field_004", {{"size_cm", {100 * field.length, 100 * field.width}}, {"goal_width_cm", 100 * field.goal_width},
                          {"posts_cm", posts_cm_json(field)}, {"yellow_goal_x_cm", 0.0}, {"blue_goal_x_cm", 100 * field.length}}},
           {"maps", {{"cell_cm", 100 * cell_m}, {"cols", m.cols}, {"rows", m.rows}, {"trials_per_cell", map_trials},
                     {"bearing_sigma_deg", m.sigma_deg}, {"cap_cm", cap_cm}, {"solvers", maps_json}}},
           {"files", {"maps_004.csv", "table1_004.json", "table1_004.md", "sim_003.json", "sim_003_paper_consecutive.png", "sim_003_paper_memory.png",
                      "sim_003_distractor_consecutive.png", "sim_003_distractor_memory.png"}}};
  dir.write("landmark_maps.json", top.dump(1) + "\n");
  dir.commit();
  out << "\nwritten: " << dir.final_dir() << "/{landmark_maps.json, maps_004.csv, map_*.png, table1_004.{json,md}, sim_003.json, sim_003_*.png}\n";
  return 0;
}

}  // namespace omniloc::experiments
