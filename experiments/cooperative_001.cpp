// Experiment "cooperative_001": paper 001's simulation. See cooperative_001.hpp and docs/cooperative.md.
#include "experiments/cooperative_001.hpp"

#include "core/json_parse.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <ostream>
#include <sstream>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "core/rng.hpp"
#include "experiments/report_format.hpp"
#include "harness/field_picture.hpp"
#include "harness/plot.hpp"
#include "harness/run_directory.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/cooperative/hough_ball.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using harness::Series;
using harness::line_plot;
using harness::png_bytes;

const char* to_string(CoopNoiseModel m) {
  switch (m) {
    case CoopNoiseModel::Cartesian: return "cartesian";
    case CoopNoiseModel::Polar: return "polar";
    case CoopNoiseModel::RobotPose: return "robot_pose";
  }
  return "unknown";
}

// --- configuration --------------------------------------------------------------------------------------

namespace {

CoopNoiseModel noise_model_from(const std::string& s) {
  if (s == "cartesian") return CoopNoiseModel::Cartesian;
  if (s == "robot_pose") return CoopNoiseModel::RobotPose;
  return CoopNoiseModel::Polar;
}

Eigen::Vector2d point_in_field(JsonReader& r, const std::string& key, const Cooperative001Config& c) {
  const std::vector<double> v = r.numbers(key, std::nullopt, 2);
  if (v[0] < 0.0 || v[0] > c.field_length || v[1] < 0.0 || v[1] > c.field_width) {
    std::ostringstream e;
    e << "a point [x, y] in metres inside the field [0, " << c.field_length << "] x [0, " << c.field_width << "]";
    throw ConfigError(r.child_path(key), json_brief(*r.raw(key)), e.str());
  }
  return {v[0], v[1]};
}

CoopTrials read_trials(JsonReader& r, const CoopTrials& d) {
  CoopTrials t;
  t.path = static_cast<int>(r.integer("path", d.path, 1, 1000000));
  t.per_subset = static_cast<int>(r.integer("per_subset", d.per_subset, 1, 100000));
  t.tracking = static_cast<int>(r.integer("tracking", d.tracking, 1, 100000));
  t.growth_model = static_cast<int>(r.integer("growth_model", d.growth_model, 2, 1000000));
  r.finish();
  return t;
}

}  // namespace

Cooperative001Config parse_cooperative_001(const Json& j) {
  Cooperative001Config c;
  JsonReader r(j, "");
  r.allow("comment");
  r.string("experiment", std::nullopt, {"cooperative_001"});
  c.description = r.string("description", std::string());

  if (auto f = r.object("field", true)) {
    f->allow("comment");
    c.field_length = f->positive("length", std::nullopt, 100.0);
    c.field_width = f->positive("width", std::nullopt, 100.0);
    f->finish();
  }

  const Json* robots = r.raw("robots", true);
  constexpr std::size_t kMaxRobots = 10;  // the robot-count figure runs all 2^n - 1 subsets
  if (!robots->is_array() || robots->empty() || robots->size() > kMaxRobots)
    throw ConfigError("/robots", json_brief(*robots), "an array of 1 to 10 robot positions [x, y] in metres");
  for (std::size_t i = 0; i < robots->size(); ++i) {
    const Json& p = (*robots)[i];
    const std::string path = json_child("/robots", i);
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number() || !std::isfinite(p[0].get<double>()) ||
        !std::isfinite(p[1].get<double>()))
      throw ConfigError(path, json_brief(p), "a robot position [x, y]: two finite numbers in metres");
    const Eigen::Vector2d v(p[0].get<double>(), p[1].get<double>());
    if (v.x() < 0.0 || v.x() > c.field_length || v.y() < 0.0 || v.y() > c.field_width) {
      std::ostringstream e;
      e << "a robot position inside the field [0, " << c.field_length << "] x [0, " << c.field_width << "] m";
      throw ConfigError(path, json_brief(p), e.str());
    }
    c.robots.push_back(v);
  }

  if (auto b = r.object("ball", true)) {
    b->allow("comment");
    c.ball_start = point_in_field(*b, "start", c);
    c.ball_end = point_in_field(*b, "end", c);
    c.ball_step = b->positive("step", 0.05, 10.0);
    c.step_time = b->positive("step_time", 0.04, 10.0);
    if ((c.ball_end - c.ball_start).norm() < c.ball_step)
      throw ConfigError(b->child_path("end"), json_brief(*b->raw("end")), "an end point at least one step (" + std::to_string(c.ball_step) + " m) from the start");
    b->finish();
  }
  if (c.path_positions() > 100000) throw ConfigError("/ball/step", std::to_string(c.ball_step), "a step giving at most 100000 positions");

  if (auto n = r.object("noise", true)) {
    n->allow("comment");
    c.noise_model = noise_model_from(n->string("model", std::string("polar"), {"polar", "cartesian", "robot_pose"}));
    c.sigma = n->number("sigma", 0.192, 0.0, 10.0);
    if (n->has("reference_distance")) c.reference_distance = n->positive("reference_distance", std::nullopt, 100.0);
    n->finish();
  }

  if (auto n = r.object("network")) {
    n->allow("comment");
    c.network = sim::NetworkConfig::from_json(*n, c.network);
    n->finish();
  }
  sim::NetworkConfig lossy;
  lossy.latency = 0.1;
  lossy.loss = 0.2;
  c.lossy_network = lossy;
  if (auto n = r.object("lossy_network")) {
    n->allow("comment");
    c.lossy_network = sim::NetworkConfig::from_json(*n, lossy);
    n->finish();
  }
  c.fusion_deadline = r.number("fusion_deadline", 0.16, 0.0, 10.0);

  if (auto t = r.object("trials")) {
    t->allow("comment");
    c.trials = read_trials(*t, c.trials);
  }
  if (auto t = r.object("quick_trials")) {
    t->allow("comment");
    c.quick_trials = read_trials(*t, c.quick_trials);
  }
  if (auto t = r.object("tracking")) {
    t->allow("comment");
    c.accel_sigma = t->positive("accel_sigma", 5.0, 100.0);
    c.particles = static_cast<int>(t->integer("particles", 100, 2, 100000));
    c.tracking_threshold = t->number("threshold", 0.5, 0.0, 1.0);
    t->finish();
  }
  if (auto g = r.object("rendered")) c.rendered = parse_coop_rendered(*g, c);
  r.finish();
  return c;
}

Cooperative001Config load_cooperative_001(const std::string& file) {
  return parse_cooperative_001(read_json_strict(file, file));
}

std::string cooperative_001_default_file() { return std::string(OMNILOC_SOURCE_DIR) + "/scenarios/experiments/cooperative_001.json"; }

void validate_cooperative_001(const std::string& file) { (void)load_cooperative_001(file); }

int Cooperative001Config::path_positions() const {
  const double len = (ball_end - ball_start).norm();
  return static_cast<int>(std::floor(len / ball_step + 1e-9)) + 1;
}

Eigen::Vector2d Cooperative001Config::ball_at(double t) const {
  const Eigen::Vector2d dir = (ball_end - ball_start).normalized();
  return ball_start + dir * (ball_step / step_time) * t;
}

double Cooperative001Config::reference_distance_or_mean() const {
  if (reference_distance) return *reference_distance;
  double s = 0.0;
  const int n = path_positions();
  for (int k = 0; k < n; ++k)
    for (const auto& r : robots) s += (ball_at(k * step_time) - r).norm();
  return s / static_cast<double>(n * static_cast<int>(robots.size()));
}

Rng cooperative_trial_rng(std::uint64_t seed, const std::string& name, int t) {
  return Rng(splitmix64(derive_seed(seed, name) + splitmix64(static_cast<std::uint64_t>(t) + 1)));
}

std::unique_ptr<BallTracker> make_coop_tracker(const Cooperative001Config& c, const std::string& name, double obs_sigma,
                                               const Eigen::Vector2d& first) {
  CvModelConfig mc;
  mc.dt = c.step_time;
  mc.accel_sigma = c.accel_sigma;
  mc.obs_sigma = std::max(1e-3, obs_sigma);
  ParticleTrackerConfig pc;
  pc.particles = c.particles;
  pc.threshold = c.tracking_threshold;
  auto tracker = make_ball_tracker(name, mc, pc);
  const double ps = mc.obs_sigma, vs = 2.0;  // m, m/s
  tracker->init(Eigen::Vector4d(first.x(), first.y(), 0.0, 0.0), Eigen::Vector4d(ps * ps, ps * ps, vs * vs, vs * vs).asDiagonal());
  return tracker;
}

// --- simulation -----------------------------------------------------------------------------------------

namespace {


struct Sighting {
  int step = 0;
  BallLine line;
};

/// One robot's sighting of the ball at B from its true position R, with the two standard normal draws
/// n1, n2 applied where `model` says the noise enters.
BallLine observe(CoopNoiseModel model, const Eigen::Vector2d& R, const Eigen::Vector2d& B, double sigma, double ref_distance,
                 double n1, double n2, double stamp) {
  BallLine l;
  l.stamp = stamp;
  switch (model) {
    case CoopNoiseModel::Cartesian:
      l.robot = R;
      l.ball_estimate = B + sigma * Eigen::Vector2d(n1, n2);
      break;
    case CoopNoiseModel::Polar: {
      const Eigen::Vector2d d = B - R;
      // A camera cannot report a negative distance: clip at 5 cm (the ball touching the robot).
      const double L = std::max(0.05, d.norm() + sigma * n1);
      const double phi = std::atan2(d.y(), d.x()) + (sigma / ref_distance) * n2;
      l.robot = R;
      l.ball_estimate = R + L * Eigen::Vector2d(std::cos(phi), std::sin(phi));
      break;
    }
    case CoopNoiseModel::RobotPose:
      l.robot = R + sigma * Eigen::Vector2d(n1, n2);
      l.ball_estimate = l.robot + (B - R);
      break;
  }
  return l;
}

struct StepFix {
  BallFix equal, weighted;
  double fuse_time = 0.0;  ///< s, when the fuser closed this stamp
  int received = 0;        ///< sightings of this stamp that arrived in time
};

struct Trial {
  std::vector<StepFix> fixes;                         ///< per step
  std::vector<std::vector<Eigen::Vector2d>> own;      ///< [step][robot]: each robot's own estimate (every robot)
  std::size_t sent = 0, lost = 0, late = 0;
};

/// One run of the ball along the path: every robot observes at every step (all robots draw noise so
/// subsets share draws), the robots in `subset` send through the network, and the fuser (at the
/// step ticks) closes a stamp when all its sightings are in or `deadline` has passed since the stamp.
Trial run_trial(const Cooperative001Config& c, CoopNoiseModel model, double ref_distance, const std::vector<int>& subset,
                const sim::NetworkConfig& net_cfg, double deadline, Rng& noise_rng, Rng& net_rng) {
  const int K = c.path_positions();
  const int nr = static_cast<int>(c.robots.size());
  Trial tr;
  tr.fixes.resize(static_cast<std::size_t>(K));
  tr.own.assign(static_cast<std::size_t>(K), std::vector<Eigen::Vector2d>(static_cast<std::size_t>(nr)));
  sim::Network<Sighting> net(net_cfg, net_rng);
  std::vector<std::vector<BallLine>> bucket(static_cast<std::size_t>(K));
  std::vector<char> closed(static_cast<std::size_t>(K), 0);
  std::vector<char> member(static_cast<std::size_t>(nr), 0);
  for (int i : subset) member[static_cast<std::size_t>(i)] = 1;
  HoughBallConfig eq_cfg, w_cfg;
  eq_cfg.weighting = BallWeighting::Equal;
  w_cfg.weighting = BallWeighting::InverseDistance;
  const int ticks = K + static_cast<int>(std::ceil(deadline / c.step_time)) + 1;
  int next_open = 0;  // stamps below this are closed
  for (int j = 0; j < ticks; ++j) {
    const double t = j * c.step_time;
    if (j < K) {
      const Eigen::Vector2d B = c.ball_at(t);
      for (int i = 0; i < nr; ++i) {
        const double n1 = noise_rng.normal(), n2 = noise_rng.normal();
        const BallLine l = observe(model, c.robots[static_cast<std::size_t>(i)], B, c.sigma, ref_distance, n1, n2, t);
        tr.own[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] = l.ball_estimate;
        if (member[static_cast<std::size_t>(i)]) net.send(sim::NetMessage<Sighting>{i, t, Sighting{j, l}}, t);
      }
    }
    for (auto& m : net.receive(t)) {
      const auto k = static_cast<std::size_t>(m.payload.step);
      if (closed[k])
        ++tr.late;
      else
        bucket[k].push_back(m.payload.line);
    }
    for (int k = next_open; k <= std::min(j, K - 1); ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (closed[ku]) continue;
      const bool complete = bucket[ku].size() == subset.size();
      if (complete || t >= k * c.step_time + deadline - 1e-9) {
        StepFix& f = tr.fixes[ku];
        f.equal = hough_ball_fix(bucket[ku], eq_cfg);
        f.weighted = hough_ball_fix(bucket[ku], w_cfg);
        f.fuse_time = t;
        f.received = static_cast<int>(bucket[ku].size());
        closed[ku] = 1;
      }
    }
    while (next_open < K && closed[static_cast<std::size_t>(next_open)]) ++next_open;
  }
  for (int k = 0; k < K; ++k) {  // cannot happen (the last tick is past every deadline); kept as a guard
    const auto ku = static_cast<std::size_t>(k);
    if (closed[ku]) continue;
    tr.fixes[ku].equal = hough_ball_fix(bucket[ku], eq_cfg);
    tr.fixes[ku].weighted = hough_ball_fix(bucket[ku], w_cfg);
    tr.fixes[ku].fuse_time = (ticks - 1) * c.step_time;
    tr.fixes[ku].received = static_cast<int>(bucket[ku].size());
  }
  tr.late += net.in_flight();
  tr.sent = net.sent();
  tr.lost = net.lost();
  return tr;
}

bool usable(const BallFix& f) { return f.status != BallFix::Status::NoObservation; }

/// Pooled error statistics over all fixes of many trials.
struct ErrorAcc {
  double sum = 0, sumsq = 0, count = 0;
  RunningStat per_trial;  ///< of the per-trial mean errors
  void add_trial(double s, double s2, double n) {
    sum += s;
    sumsq += s2;
    count += n;
    if (n > 0) per_trial.add(s / n);
  }
  double mean() const { return count > 0 ? sum / count : 0.0; }
  double rms_per_axis() const { return count > 0 ? std::sqrt(sumsq / count / 2.0) : 0.0; }
};

struct PathStats {
  ErrorAcc single;             ///< each robot's own estimate, pooled over robots
  std::vector<ErrorAcc> own;   ///< per robot
  ErrorAcc equal, weighted;    ///< at the stamp
  ErrorAcc weighted_at_use;    ///< weighted fix against the ball when the fix was made
  RunningStat diff;                   ///< per trial: weighted mean - equal mean
  std::map<std::string, double> status_equal, status_weighted;
  double sent = 0, lost = 0, late = 0, age_sum = 0, age_n = 0, received_sum = 0;
  int trials = 0;
};

void accumulate(PathStats& s, const Cooperative001Config& c, const Trial& tr, bool with_own) {
  const int K = c.path_positions();
  const std::size_t nr = c.robots.size();
  if (s.own.size() != nr) s.own.resize(nr);
  double es = 0, es2 = 0, en = 0, ws = 0, ws2 = 0, wn = 0, us = 0, us2 = 0, un = 0;
  for (int k = 0; k < K; ++k) {
    const double tk = k * c.step_time;
    const Eigen::Vector2d B = c.ball_at(tk);
    const StepFix& f = tr.fixes[static_cast<std::size_t>(k)];
    s.status_equal[to_string(f.equal.status)] += 1;
    s.status_weighted[to_string(f.weighted.status)] += 1;
    s.received_sum += f.received;
    if (usable(f.equal)) {
      const double e = (f.equal.position - B).norm();
      es += e, es2 += e * e, en += 1;
    }
    if (usable(f.weighted)) {
      const double e = (f.weighted.position - B).norm();
      ws += e, ws2 += e * e, wn += 1;
      const double u = (f.weighted.position - c.ball_at(f.fuse_time)).norm();
      us += u, us2 += u * u, un += 1;
      s.age_sum += f.fuse_time - tk;
      s.age_n += 1;
    }
  }
  if (with_own)
    for (std::size_t i = 0; i < nr; ++i) {
      double os = 0, os2 = 0;
      for (int k = 0; k < K; ++k) {
        const double e = (tr.own[static_cast<std::size_t>(k)][i] - c.ball_at(k * c.step_time)).norm();
        os += e, os2 += e * e;
      }
      s.own[i].add_trial(os, os2, K);
      s.single.add_trial(os, os2, K);
    }
  s.equal.add_trial(es, es2, en);
  s.weighted.add_trial(ws, ws2, wn);
  s.weighted_at_use.add_trial(us, us2, un);
  if (en > 0 && wn > 0) s.diff.add(ws / wn - es / en);
  s.sent += static_cast<double>(tr.sent);
  s.lost += static_cast<double>(tr.lost);
  s.late += static_cast<double>(tr.late);
  ++s.trials;
}

std::vector<int> all_robots(const Cooperative001Config& c) {
  std::vector<int> v(c.robots.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int>(i);
  return v;
}

PathStats run_path(const Cooperative001Config& c, CoopNoiseModel model, const sim::NetworkConfig& net, const char* net_stream,
                   int trials, std::uint64_t seed) {
  PathStats s;
  const double ref = c.reference_distance_or_mean();
  const std::vector<int> team = all_robots(c);
  for (int t = 0; t < trials; ++t) {
    Rng noise = cooperative_trial_rng(seed, "path/noise", t);  // the same observations for every model and network
    Rng netr = cooperative_trial_rng(seed, net_stream, t);
    accumulate(s, c, run_trial(c, model, ref, team, net, c.fusion_deadline, noise, netr), true);
  }
  return s;
}

cv::Mat field_figure(const Cooperative001Config& c, const Trial& tr) {
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

}  // namespace

// --- the experiment -------------------------------------------------------------------------------------

int run_cooperative_001(const ExperimentArgs& args, std::ostream& out) {
  const auto t_start = std::chrono::steady_clock::now();
  const std::string file = args.config.empty() ? cooperative_001_default_file() : args.config;
  const Cooperative001Config c = load_cooperative_001(file);
  const CoopTrials n = args.quick ? c.quick_trials : c.trials;
  const std::uint64_t seed = args.seed;
  const double ref = c.reference_distance_or_mean();
  const Json paper = read_published();
  const double p_equal = published_number(paper, "001_cooperative_mean_error_mm", "equal_weights") / 1000.0;
  const double p_weighted = published_number(paper, "001_cooperative_mean_error_mm", "weighted") / 1000.0;
  RunDirectory dir(args.out_dir);
  std::ostringstream md;  // the markdown report, also printed

  md << "# cooperative_001: paper 001 simulation\n\n";
  if (!c.description.empty()) md << c.description << "\n\n";
  md
     << "Description file `" << file << "`; seed " << seed << (args.quick ? " (quick mode)" : "") << "; machine: " << machine_text() << ".\n"
     << strprintf("Field %.1f m x %.1f m, ", c.field_length, c.field_width) << c.robots.size() << " robots, ball "
     << strprintf("(%.0f, %.0f) -> (%.0f, %.0f) mm", 1000 * c.ball_start.x(), 1000 * c.ball_start.y(), 1000 * c.ball_end.x(), 1000 * c.ball_end.y())
     << strprintf(" in %.0f mm steps (%d positions, %.3f s per step). ", 1000 * c.ball_step, c.path_positions(), c.step_time)
     << "Noise model **" << to_string(c.noise_model) << "**, sigma " << mm(c.sigma, 0) << " mm"
     << (c.noise_model == CoopNoiseModel::Polar ? strprintf(" (bearing sigma %.2f deg = sigma / L_ref, L_ref = %.0f mm)", 180.0 / std::numbers::pi * c.sigma / ref, 1000 * ref)
                                                 : std::string())
     << ".\n\n";

  // 1. Headline: every noise model, the configured (default ideal) network, full team.
  const CoopNoiseModel models[] = {CoopNoiseModel::Polar, CoopNoiseModel::Cartesian, CoopNoiseModel::RobotPose};
  std::map<CoopNoiseModel, PathStats> by_model;
  for (CoopNoiseModel m : models) by_model[m] = run_path(c, m, c.network, "path/net", n.path, seed);
  const PathStats& head = by_model[c.noise_model];

  md << "## Mean error over the path, " << n.path << " trials, all " << c.robots.size() << " robots (network: latency "
     << c.network.latency << " s, loss " << c.network.loss << ")\n\n"
     << "| estimate | mean error (mm) | per-trial std (mm) | paper (mm) |\n|---|---|---|---|\n"
     << "| one robot's own estimate (mean over robots) | " << mm(head.single.mean()) << " | " << mm(head.single.per_trial.sd()) << " | - |\n"
     << "| Hough fix, equal weights | " << mm(head.equal.mean()) << " | " << mm(head.equal.per_trial.sd()) << " | " << mm(p_equal, 0) << " |\n"
     << "| Hough fix, K_i = 1/L_i | " << mm(head.weighted.mean()) << " | " << mm(head.weighted.per_trial.sd()) << " | " << mm(p_weighted, 0) << " |\n"
     << "| paired difference 1/L - equal (mean +- s.e.) | " << mm(head.diff.mean) << " +- " << mm(head.diff.se()) << " | "
     << mm(head.diff.sd()) << " | " << mm(p_weighted - p_equal, 0) << " |\n\n";
  const double real_before = published_number(paper, "001_real_mean_error_cm", "before"), real_after = published_number(paper, "001_real_mean_error_cm", "after");
  if (!std::isnan(real_before))
    md << strprintf("Paper's real-robot result (not simulated here): mean error %.1f cm -> %.1f cm. ", real_before, real_after)
       << "The paper does not say where its simulated noise enters; the next table runs the same draws through three readings.\n\n";

  md << "Same observations under each noise model (sigma " << mm(c.sigma, 0) << " mm; mean error in mm):\n\n"
     << "| noise model | where the noise enters | own estimate | equal weights | K = 1/L | 1/L - equal (+- s.e.) |\n|---|---|---|---|---|---|\n";
  for (CoopNoiseModel m : models) {
    const PathStats& s = by_model[m];
    const char* where = m == CoopNoiseModel::Polar       ? "distance N(0, sigma^2), bearing N(0, (sigma/L_ref)^2)"
                        : m == CoopNoiseModel::Cartesian ? "ball position reported by each robot, N(0, sigma^2 I)"
                                                         : "robot's own position, N(0, sigma^2 I); relative sighting exact";
    md << "| " << to_string(m) << (m == c.noise_model ? " (headline)" : "") << " | " << where << " | " << mm(s.single.mean()) << " | "
       << mm(s.equal.mean()) << " | " << mm(s.weighted.mean()) << " | " << mm(s.diff.mean) << " +- " << mm(s.diff.se()) << " |\n";
  }
  md << "\nPer robot (headline model), own-estimate mean error in mm:";
  for (std::size_t i = 0; i < head.own.size(); ++i) md << strprintf(" robot %d: ", static_cast<int>(i) + 1) << mm(head.own[i].mean());
  md << ".\n\n";

  // 2. Network: ideal vs lossy, fixes used at their stamps.
  const PathStats lossy = run_path(c, c.noise_model, c.lossy_network, "path/lossy_net", n.path, seed);
  auto net_row = [&](const char* name, const sim::NetworkConfig& nc, const PathStats& s) {
    const double steps = static_cast<double>(s.trials) * c.path_positions();
    std::ostringstream r;
    r << "| " << name << strprintf(" (latency %.3g s, jitter %.3g s ", nc.latency, nc.jitter) << sim::to_string(nc.jitter_kind)
      << strprintf(", loss %.2g)", nc.loss) << " | " << strprintf("%.1f %%", 100.0 * s.lost / std::max(1.0, s.sent)) << " | "
      << strprintf("%.2f %%", 100.0 * s.late / std::max(1.0, s.sent)) << " | " << strprintf("%.2f", s.received_sum / steps) << " | "
      << strprintf("%.2f %%", 100.0 * (s.status_weighted.count("single_robot") ? s.status_weighted.at("single_robot") : 0.0) / steps) << " | "
      << strprintf("%.2f %%", 100.0 * (s.status_weighted.count("no_observation") ? s.status_weighted.at("no_observation") : 0.0) / steps) << " | "
      << mm(s.equal.mean()) << " | " << mm(s.weighted.mean()) << " | " << strprintf("%.0f", 1000.0 * (s.age_n > 0 ? s.age_sum / s.age_n : 0.0)) << " | "
      << mm(s.weighted_at_use.mean()) << " |\n";
    return r.str();
  };
  md << "## Network (headline noise model, " << n.path << " trials; fusion deadline " << c.fusion_deadline << " s after the stamp)\n\n"
     << "Fixes are computed per time stamp from the sightings of that stamp that arrived in time and compared with the ball **at the "
        "stamp**; the last column compares the same fix with the ball when the fix was made (what a robot acting on it without "
        "prediction would see).\n\n"
     << "| network | lost | late | sightings per fix | single-robot fixes | no fix | equal (mm) | 1/L (mm) | fix age (ms) | 1/L vs ball at fuse time (mm) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n"
     << net_row("configured", c.network, head) << net_row("lossy", c.lossy_network, lossy) << "\n";

  // 3. Error against the number of robots (paper fig. 10): every subset of each size, per_subset trials each.
  const int nr = static_cast<int>(c.robots.size());
  std::vector<RunningStat> eq_all(static_cast<std::size_t>(nr) + 1), w_all(static_cast<std::size_t>(nr) + 1);
  std::vector<double> eq_first(static_cast<std::size_t>(nr) + 1), w_first(static_cast<std::size_t>(nr) + 1);
  std::vector<double> degenerate(static_cast<std::size_t>(nr) + 1), fixes_k(static_cast<std::size_t>(nr) + 1);
  std::vector<int> subsets_k(static_cast<std::size_t>(nr) + 1);
  std::vector<std::vector<double>> w_errors(static_cast<std::size_t>(nr) + 1);  // every 1/L fix error, all subsets
  for (unsigned mask = 1; mask < (1u << nr); ++mask) {
    std::vector<int> subset;
    for (int i = 0; i < nr; ++i)
      if (mask & (1u << i)) subset.push_back(i);
    const auto k = subset.size();
    PathStats s;
    for (int t = 0; t < n.per_subset; ++t) {
      Rng noise = cooperative_trial_rng(seed, "robots/noise", t);  // shared by every subset: subsets differ only in who is asked
      Rng netr = cooperative_trial_rng(seed, "robots/net", t);
      const Trial tr = run_trial(c, c.noise_model, ref, subset, c.network, c.fusion_deadline, noise, netr);
      accumulate(s, c, tr, false);
      for (int k = 0; k < c.path_positions(); ++k) {
        const StepFix& f = tr.fixes[static_cast<std::size_t>(k)];
        if (usable(f.weighted)) w_errors[subset.size()].push_back((f.weighted.position - c.ball_at(k * c.step_time)).norm());
      }
    }
    eq_all[k].add(s.equal.mean());
    w_all[k].add(s.weighted.mean());
    ++subsets_k[k];
    degenerate[k] += s.status_weighted.count("degenerate") ? s.status_weighted.at("degenerate") : 0.0;
    fixes_k[k] += static_cast<double>(s.trials) * c.path_positions();
    if (mask == (1u << k) - 1) {  // the first k robots
      eq_first[k] = s.equal.mean();
      w_first[k] = s.weighted.mean();
    }
  }
  md << "## Error against the number of robots (paper fig. 10), " << n.per_subset
     << " trials per subset, mean over **every subset** of that size (and the first k robots of the list)\n\n"
     << "| robots | subsets | equal, all subsets (mm) | 1/L, all subsets (mm) | equal, first k (mm) | 1/L, first k (mm) | 1/L median, all subsets (mm) | degenerate fixes |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  std::string csv = "robots,subsets,trials_per_subset,equal_all_subsets_mm,weighted_all_subsets_mm,equal_first_k_mm,weighted_first_k_mm,degenerate_fraction\n";
  Series s_eq{"equal, all subsets", {}, {}}, s_w{"1/L, all subsets", {}, {}}, s_eqf{"equal, first k", {}, {}}, s_wf{"1/L, first k", {}, {}};
  Json robots_json = Json::array();
  for (int k = 1; k <= nr; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const double deg = degenerate[ku] / std::max(1.0, fixes_k[ku]);
    std::vector<double>& we = w_errors[ku];
    std::nth_element(we.begin(), we.begin() + static_cast<std::ptrdiff_t>(we.size() / 2), we.end());
    const double w_median = we.empty() ? 0.0 : we[we.size() / 2];
    md << "| " << k << " | " << subsets_k[ku] << " | " << mm(eq_all[ku].mean) << " | " << mm(w_all[ku].mean) << " | " << mm(eq_first[ku]) << " | "
       << mm(w_first[ku]) << " | " << mm(w_median) << " | " << strprintf("%.2f %%", 100.0 * deg) << " |\n";
    csv += strprintf("%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.5f\n", k, subsets_k[ku], n.per_subset, 1000 * eq_all[ku].mean, 1000 * w_all[ku].mean,
              1000 * eq_first[ku], 1000 * w_first[ku], deg);
    for (Series* se : {&s_eq, &s_w, &s_eqf, &s_wf}) se->x.push_back(k);
    s_eq.y.push_back(1000 * eq_all[ku].mean);
    s_w.y.push_back(1000 * w_all[ku].mean);
    s_eqf.y.push_back(1000 * eq_first[ku]);
    s_wf.y.push_back(1000 * w_first[ku]);
    robots_json.push_back({{"robots", k}, {"subsets", subsets_k[ku]}, {"equal_all_mm", 1000 * eq_all[ku].mean}, {"weighted_all_mm", 1000 * w_all[ku].mean},
                           {"equal_first_k_mm", 1000 * eq_first[ku]}, {"weighted_first_k_mm", 1000 * w_first[ku]}, {"weighted_median_all_mm", 1000 * w_median},
                           {"degenerate_fraction", deg}});
  }
  md << "\nWith one robot both weightings give that robot's own estimate (bearing and distance). Two robots whose lines "
        "to the ball meet at a small angle give a long error ellipse along the lines, hence the large means (and the gap to the median) "
        "at 2 robots. Degenerate fixes (lines within about "
        "1.15 degrees of each other) fall back to the weighted mean of the robots' own estimates and are included in the means.\n\n";
  dir.write("robots_vs_error.csv", csv);
  dir.write("robots_vs_error.png",
            png_bytes(line_plot({s_eq, s_w, s_eqf, s_wf}, "Mean error vs number of robots (paper 001 fig. 10), noise " + std::string(to_string(c.noise_model)),
                                "number of robots", "mean error (mm)")));

  // 4. Growth-model benchmark: FBPF vs MFBPF (and the bootstrap PF), paired runs.
  const ParticleFilterKind kinds[] = {ParticleFilterKind::Bootstrap, ParticleFilterKind::Fission, ParticleFilterKind::ModifiedFission};
  std::vector<double> rm[3];
  for (int i = 0; i < n.growth_model; ++i)
    for (int k = 0; k < 3; ++k) {
      Rng rng = cooperative_trial_rng(seed, "growth", i);  // every filter sees the same trajectory
      rm[k].push_back(growth_model_rmse(kinds[k], 100, 50, rng));
    }
  Json growth_json = Json::object();
  md << "## Growth-model benchmark (paper 5.3), " << n.growth_model << " paired Monte Carlo runs, 50 steps, 100 particles, N_th = 50\n\n"
     << "| filter | mean RMSE | std | median |\n|---|---|---|---|\n";
  for (int k = 0; k < 3; ++k) {
    RunningStat st;
    for (double v : rm[k]) st.add(v);
    std::vector<double> sorted = rm[k];
    std::sort(sorted.begin(), sorted.end());
    const std::size_t h = sorted.size() / 2;
    const double med = sorted.size() % 2 ? sorted[h] : 0.5 * (sorted[h - 1] + sorted[h]);
    md << "| " << to_string(kinds[k]) << strprintf(" | %.3f | %.3f | %.3f |\n", st.mean, st.sd(), med);
    growth_json[to_string(kinds[k])] = {{"mean", st.mean}, {"std", st.sd()}, {"median", med}};
  }
  auto paired = [&](int a, int b) {
    RunningStat d;
    int lower = 0;
    for (std::size_t i = 0; i < rm[a].size(); ++i) {
      d.add(rm[a][i] - rm[b][i]);
      lower += rm[a][i] < rm[b][i];
    }
    growth_json[std::string(to_string(kinds[a])) + "_minus_" + to_string(kinds[b])] = {{"mean", d.mean}, {"se", d.se()}, {"a_lower", lower}};
    return strprintf("%.3f +- %.3f (", d.mean, d.se()) + to_string(kinds[a]) + strprintf(" lower in %d of %d runs)", lower, static_cast<int>(rm[a].size()));
  };
  const std::string d_mf = paired(2, 1), d_fp = paired(1, 0);
  const double dm = growth_json["mfbpf_minus_fbpf"]["mean"].get<double>(), dse = growth_json["mfbpf_minus_fbpf"]["se"].get<double>();
  const double z = dse > 0.0 ? dm / dse : 0.0;
  const std::string verdict = z < -2.0  ? strprintf("reproduced: MFBPF is lower by %.3f (%.1f standard errors)", -dm, -z)
                              : z < 0.0 ? strprintf("not established: MFBPF is lower by %.3f, only %.1f standard errors", -dm, -z)
                                        : strprintf("not reproduced: MFBPF is not lower (MFBPF - FBPF = %+.3f, %.1f standard errors)", dm, z);
  md << "\nPaired differences (mean +- standard error): MFBPF - FBPF = " << d_mf << "; FBPF - PF = " << d_fp << ".\n"
     << "Paper's claim: "
     << (paper.contains("001_growth_model") && paper["001_growth_model"].contains("claim") ? paper["001_growth_model"]["claim"].get<std::string>()
                                                                                           : std::string("n/a"))
     << " (one run shown). Here: **" << verdict << "**.\n\n";
  growth_json["verdict"] = verdict;

  // 5. Tracking: the four trackers fed with different inputs.
  struct Input {
    std::string name;
    double obs_sigma;  ///< per-axis RMS error of this input, measured above (a calibration of the tracker's R)
  };
  std::vector<Input> inputs = {{"1/L fix", head.weighted.rms_per_axis()},
                               {"equal fix", head.equal.rms_per_axis()},
                               {"1/L fix, lossy network", lossy.weighted.rms_per_axis()}};
  for (int i = 0; i < nr; ++i) inputs.push_back({"robot " + std::to_string(i + 1) + " own", head.own[static_cast<std::size_t>(i)].rms_per_axis()});
  const std::vector<std::string> trackers = {"kf", "pf", "fbpf", "mfbpf"};
  const int K = c.path_positions();
  const int settle = std::min(10, K - 1);
  // err[input][tracker + 1] (0 = the input itself), pooled over steps: all steps and steps >= settle.
  std::vector<std::vector<std::array<double, 4>>> acc(inputs.size(), std::vector<std::array<double, 4>>(trackers.size() + 1, {0, 0, 0, 0}));
  for (int t = 0; t < n.tracking; ++t) {
    Rng noise = cooperative_trial_rng(seed, "tracking/noise", t), noise2 = cooperative_trial_rng(seed, "tracking/noise", t);
    Rng net1 = cooperative_trial_rng(seed, "tracking/net", t), net2 = cooperative_trial_rng(seed, "tracking/lossy_net", t);
    const Trial ideal = run_trial(c, c.noise_model, ref, all_robots(c), c.network, c.fusion_deadline, noise, net1);
    const Trial lossy_tr = run_trial(c, c.noise_model, ref, all_robots(c), c.lossy_network, c.fusion_deadline, noise2, net2);
    for (std::size_t in = 0; in < inputs.size(); ++in) {
      std::vector<std::optional<Eigen::Vector2d>> z(static_cast<std::size_t>(K));
      for (int k = 0; k < K; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        if (in == 0 && usable(ideal.fixes[ku].weighted)) z[ku] = ideal.fixes[ku].weighted.position;
        if (in == 1 && usable(ideal.fixes[ku].equal)) z[ku] = ideal.fixes[ku].equal.position;
        if (in == 2 && usable(lossy_tr.fixes[ku].weighted)) z[ku] = lossy_tr.fixes[ku].weighted.position;
        if (in >= 3) z[ku] = ideal.own[ku][in - 3];
      }
      for (std::size_t tk = 0; tk <= trackers.size(); ++tk) {
        std::unique_ptr<BallTracker> tracker;
        Eigen::Vector2d first = c.ball_start;
        for (const auto& zz : z)
          if (zz) {
            first = *zz;
            break;
          }
        if (tk > 0) tracker = make_coop_tracker(c, trackers[tk - 1], inputs[in].obs_sigma, first);
        Rng frng = cooperative_trial_rng(seed, ("tracking/filter/" + (tk ? trackers[tk - 1] : std::string("none"))).c_str(), t);
        for (int k = 0; k < K; ++k) {
          const auto ku = static_cast<std::size_t>(k);
          const Eigen::Vector2d B = c.ball_at(k * c.step_time);
          double e;
          if (tk == 0) {
            if (!z[ku]) continue;
            e = (*z[ku] - B).norm();
          } else {
            e = (tracker->step(z[ku], frng).state.head<2>() - B).norm();
          }
          auto& a = acc[in][tk];
          a[0] += e, a[1] += 1;
          if (k >= settle) a[2] += e, a[3] += 1;
        }
      }
    }
  }
  auto cell = [&](std::size_t in, std::size_t tk) {
    const auto& a = acc[in][tk];
    return strprintf("%.0f (%.0f)", 1000 * a[0] / std::max(1.0, a[1]), 1000 * a[2] / std::max(1.0, a[3]));
  };
  md << "## Tracking (" << n.tracking << " trials; mean position error in mm over all " << K << " steps, in brackets over steps " << settle
     << "-" << K - 1 << ")\n\n"
     << "Trackers: constant-velocity model, dt " << c.step_time << " s, accel_sigma " << c.accel_sigma << " m/s^2, " << c.particles
     << " particles; obs_sigma per input = its per-axis RMS error measured in the path trials; prior at the first input, velocity std 2 m/s. "
        "'own' inputs are one robot's raw sighting (no cooperation); the lossy-network input is used in stamp order.\n\n"
     << "| tracker |";
  for (const auto& in : inputs) md << " " << in.name << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < inputs.size(); ++i) md << "---|";
  md << "\n| obs_sigma (mm) |";
  for (const auto& in : inputs) md << " " << mm(in.obs_sigma, 0) << " |";
  Json tracking_json = Json::object();
  for (std::size_t tk = 0; tk <= trackers.size(); ++tk) {
    const std::string tname = tk ? trackers[tk - 1] : std::string("input itself (no tracker)");
    md << "\n| " << tname << " |";
    for (std::size_t in = 0; in < inputs.size(); ++in) {
      md << " " << cell(in, tk) << " |";
      const auto& a = acc[in][tk];
      tracking_json[tname][inputs[in].name] = {{"mean_mm", 1000 * a[0] / std::max(1.0, a[1])}, {"mean_after_settle_mm", 1000 * a[2] / std::max(1.0, a[3])}};
    }
  }
  md << "\n\n";

  // 6. Rendered-image mode: the same path seen through each robot's own camera.
  Json rendered_json = nullptr;
  if (c.rendered) rendered_json = run_cooperative_rendered(c, args.quick ? c.rendered->quick_trials : c.rendered->trials, seed, md, dir, &out);

  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  md << strprintf("Run time %.1f s.\n", elapsed);

  // Outputs.
  auto stats_json = [&](const PathStats& s) {
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
  };
  Json models_json = Json::object();
  for (CoopNoiseModel m : models) models_json[to_string(m)] = stats_json(by_model[m]);
  Json j{{"experiment", "cooperative_001"},
         {"seed", seed},
         {"quick", args.quick},
         {"config_file", file},
         {"machine", machine_text()},
         {"noise_model", to_string(c.noise_model)},
         {"sigma_m", c.sigma},
         {"reference_distance_m", ref},
         {"trials", {{"path", n.path}, {"per_subset", n.per_subset}, {"tracking", n.tracking}, {"growth_model", n.growth_model}}},
         {"paper", {{"equal_mm", 1000 * p_equal}, {"weighted_mm", 1000 * p_weighted}}},
         {"headline", stats_json(head)},
         {"noise_models", models_json},
         {"lossy_network", stats_json(lossy)},
         {"robots_vs_error", robots_json},
         {"growth_model", growth_json},
         {"tracking", tracking_json},
         {"rendered", rendered_json},
         {"elapsed_s", elapsed}};
  if (std::isnan(p_equal)) j["paper"] = nullptr;
  dir.write("cooperative_001.json", j.dump(1) + "\n");
  dir.write("cooperative_001.md", md.str());
  {
    Rng noise = cooperative_trial_rng(seed, "path/noise", 0), netr = cooperative_trial_rng(seed, "path/net", 0);
    dir.write("field.png", png_bytes(field_figure(c, run_trial(c, c.noise_model, ref, all_robots(c), c.network, c.fusion_deadline, noise, netr))));
  }
  dir.commit();
  out << md.str() << "files: " << dir.final_dir() << "/{cooperative_001.json,cooperative_001.md,robots_vs_error.png,robots_vs_error.csv,field.png"
      << (c.rendered ? ",robots_vs_error_rendered.png,robots_vs_error_rendered.csv" : "") << "}\n";
  return 0;
}

}  // namespace omniloc::experiments
