// Experiment "cooperative_001": paper 001's simulation, direct-noise mode, and the experiment's run
// (configuration -> both modes' computation -> report). See cooperative_001.hpp and docs/cooperative.md.
#include "experiments/cooperative_001.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "core/rng.hpp"
#include "experiments/cooperative_001_report.hpp"
#include "experiments/cooperative_001_results.hpp"
#include "harness/run_directory.hpp"
#include "localization/cooperative/ball_trackers.hpp"
#include "localization/cooperative/hough_ball.hpp"

namespace omniloc::experiments {

// --- result accessors -----------------------------------------------------------------------------------

void CoopErrorAcc::add_trial(double s, double s2, double n) {
  sum += s;
  sumsq += s2;
  count += n;
  if (n > 0) per_trial.add(s / n);
}

double CoopErrorAcc::mean() const { return count > 0 ? sum / count : 0.0; }

double CoopErrorAcc::rms_per_axis() const { return count > 0 ? std::sqrt(sumsq / count / 2.0) : 0.0; }

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

/// One run of the ball along the path: every robot observes at every step (all robots draw noise so
/// subsets share draws), the robots in `subset` send through the network, and the fuser (at the
/// step ticks) closes a stamp when all its sightings are in or `deadline` has passed since the stamp.
CoopTrial run_trial(const Cooperative001Config& c, CoopNoiseModel model, double ref_distance, const std::vector<int>& subset,
                const sim::NetworkConfig& net_cfg, double deadline, Rng& noise_rng, Rng& net_rng) {
  const int K = c.path_positions();
  const int nr = static_cast<int>(c.robots.size());
  CoopTrial tr;
  tr.fixes.resize(static_cast<std::size_t>(K));
  tr.own.assign(static_cast<std::size_t>(K), std::vector<Eigen::Vector2d>(static_cast<std::size_t>(nr)));
  sim::Network<Sighting> net(net_cfg, net_rng);
  std::vector<std::vector<BallLine>> bucket(static_cast<std::size_t>(K));
  std::vector<char> closed(static_cast<std::size_t>(K), 0);
  std::vector<char> member(static_cast<std::size_t>(nr), 0);
  for (int i : subset) member[static_cast<std::size_t>(i)] = 1;
  const HoughBallConfig eq_cfg = coop_hough_config(BallWeighting::Equal), w_cfg = coop_hough_config(BallWeighting::InverseDistance);
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
        CoopStepFix& f = tr.fixes[ku];
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

void accumulate(CoopPathStats& s, const Cooperative001Config& c, const CoopTrial& tr, bool with_own) {
  const int K = c.path_positions();
  const std::size_t nr = c.robots.size();
  if (s.own.size() != nr) s.own.resize(nr);
  double es = 0, es2 = 0, en = 0, ws = 0, ws2 = 0, wn = 0, us = 0, us2 = 0, un = 0;
  for (int k = 0; k < K; ++k) {
    const double tk = k * c.step_time;
    const Eigen::Vector2d B = c.ball_at(tk);
    const CoopStepFix& f = tr.fixes[static_cast<std::size_t>(k)];
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

CoopPathStats run_path(const Cooperative001Config& c, CoopNoiseModel model, const sim::NetworkConfig& net, const char* net_stream,
                   int trials, std::uint64_t seed) {
  CoopPathStats s;
  const double ref = c.reference_distance_or_mean();
  const std::vector<int> team = all_robots(c);
  for (int t = 0; t < trials; ++t) {
    Rng noise = cooperative_trial_rng(seed, "path/noise", t);  // the same observations for every model and network
    Rng netr = cooperative_trial_rng(seed, net_stream, t);
    accumulate(s, c, run_trial(c, model, ref, team, net, c.fusion_deadline, noise, netr), true);
  }
  return s;
}


/// Error against the number of robots (paper fig. 10): every subset of each size, per_subset trials each.
std::vector<CoopRobotCount> robots_vs_error(const Cooperative001Config& c, int per_subset, double ref, std::uint64_t seed) {
  const int nr = static_cast<int>(c.robots.size());
  const auto n1 = static_cast<std::size_t>(nr) + 1;
  std::vector<RunningStat> eq_all(n1), w_all(n1);
  std::vector<double> eq_first(n1), w_first(n1), degenerate(n1), fixes_k(n1);
  std::vector<int> subsets_k(n1);
  std::vector<std::vector<double>> w_errors(n1);  // every 1/L fix error, all subsets
  for (unsigned mask = 1; mask < (1u << nr); ++mask) {
    std::vector<int> subset;
    for (int i = 0; i < nr; ++i)
      if (mask & (1u << i)) subset.push_back(i);
    const auto k = subset.size();
    CoopPathStats s;
    for (int t = 0; t < per_subset; ++t) {
      Rng noise = cooperative_trial_rng(seed, "robots/noise", t);  // shared by every subset: subsets differ only in who is asked
      Rng netr = cooperative_trial_rng(seed, "robots/net", t);
      const CoopTrial tr = run_trial(c, c.noise_model, ref, subset, c.network, c.fusion_deadline, noise, netr);
      accumulate(s, c, tr, false);
      for (int step = 0; step < c.path_positions(); ++step) {
        const CoopStepFix& f = tr.fixes[static_cast<std::size_t>(step)];
        if (usable(f.weighted)) w_errors[k].push_back((f.weighted.position - c.ball_at(step * c.step_time)).norm());
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
  std::vector<CoopRobotCount> rows;
  for (std::size_t k = 1; k < n1; ++k)
    rows.push_back({static_cast<int>(k), subsets_k[k], eq_all[k].mean, w_all[k].mean, eq_first[k], w_first[k],
                    w_errors[k].empty() ? 0.0 : quantile(w_errors[k], 0.5), degenerate[k] / std::max(1.0, fixes_k[k])});
  return rows;
}

/// Growth-model benchmark: FBPF vs MFBPF (and the bootstrap PF), paired runs on the same trajectories.
CoopGrowth growth_model(int runs, std::uint64_t seed) {
  const ParticleFilterKind kinds[] = {ParticleFilterKind::Bootstrap, ParticleFilterKind::Fission, ParticleFilterKind::ModifiedFission};
  std::vector<double> rm[3];
  for (int i = 0; i < runs; ++i)
    for (int k = 0; k < 3; ++k) {
      Rng rng = cooperative_trial_rng(seed, "growth", i);  // every filter sees the same trajectory
      rm[k].push_back(growth_model_rmse(kinds[k], 100, 50, rng));
    }
  CoopGrowth g;
  g.runs = runs;
  for (int k = 0; k < 3; ++k) {
    RunningStat st;
    for (double v : rm[k]) st.add(v);
    g.filters.push_back({kinds[k], st.mean, st.sd(), median(rm[k])});
  }
  auto paired = [&](int a, int b) {
    RunningStat d;
    int lower = 0;
    for (std::size_t i = 0; i < rm[a].size(); ++i) {
      d.add(rm[a][i] - rm[b][i]);
      lower += rm[a][i] < rm[b][i];
    }
    return CoopGrowth::Paired{kinds[a], kinds[b], d.mean, d.se(), lower};
  };
  g.mfbpf_minus_fbpf = paired(2, 1);
  g.fbpf_minus_pf = paired(1, 0);
  return g;
}

/// The tracker inputs of one tracking trial: fix sequences and every robot's own sightings.
std::vector<CoopFixSequence> tracking_inputs(const Cooperative001Config& c, const CoopTrial& ideal, const CoopTrial& lossy, std::size_t count) {
  const int K = c.path_positions();
  std::vector<CoopFixSequence> z(count, CoopFixSequence(static_cast<std::size_t>(K)));
  for (std::size_t in = 0; in < count; ++in)
    for (int k = 0; k < K; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (in == 0 && usable(ideal.fixes[ku].weighted)) z[in][ku] = ideal.fixes[ku].weighted.position;
      if (in == 1 && usable(ideal.fixes[ku].equal)) z[in][ku] = ideal.fixes[ku].equal.position;
      if (in == 2 && usable(lossy.fixes[ku].weighted)) z[in][ku] = lossy.fixes[ku].weighted.position;
      if (in >= 3) z[in][ku] = ideal.own[ku][in - 3];
    }
  return z;
}

/// The four trackers fed with the 1/L fix, the equal fix, the lossy 1/L fix and each robot's own sighting.
CoopTracking tracking(const Cooperative001Config& c, int trials, double ref, const CoopPathStats& head, const CoopPathStats& lossy,
                      std::uint64_t seed) {
  CoopTracking r;
  r.inputs = {{"1/L fix", head.weighted.rms_per_axis()}, {"equal fix", head.equal.rms_per_axis()}, {"1/L fix, lossy network", lossy.weighted.rms_per_axis()}};
  for (std::size_t i = 0; i < c.robots.size(); ++i) r.inputs.push_back({"robot " + std::to_string(i + 1) + " own", head.own[i].rms_per_axis()});
  const auto& trackers = coop_trackers();
  r.trials = trials;
  r.steps = c.path_positions();
  r.settle = std::min(10, r.steps - 1);
  r.acc.assign(r.inputs.size(), std::vector<std::array<double, 4>>(trackers.size() + 1, {0, 0, 0, 0}));
  auto add = [&](std::array<double, 4>& a, int k, double e) {
    a[0] += e, a[1] += 1;
    if (k >= r.settle) a[2] += e, a[3] += 1;
  };
  for (int t = 0; t < trials; ++t) {
    Rng noise = cooperative_trial_rng(seed, "tracking/noise", t), noise2 = cooperative_trial_rng(seed, "tracking/noise", t);
    Rng net1 = cooperative_trial_rng(seed, "tracking/net", t), net2 = cooperative_trial_rng(seed, "tracking/lossy_net", t);
    const CoopTrial ideal = run_trial(c, c.noise_model, ref, all_robots(c), c.network, c.fusion_deadline, noise, net1);
    const CoopTrial lossy_tr = run_trial(c, c.noise_model, ref, all_robots(c), c.lossy_network, c.fusion_deadline, noise2, net2);
    const std::vector<CoopFixSequence> z = tracking_inputs(c, ideal, lossy_tr, r.inputs.size());
    for (std::size_t in = 0; in < r.inputs.size(); ++in) {
      for (int k = 0; k < r.steps; ++k)  // the input itself
        if (const auto& zk = z[in][static_cast<std::size_t>(k)]) add(r.acc[in][0], k, (*zk - c.ball_at(k * c.step_time)).norm());
      const Eigen::Vector2d first = first_fix(z[in]).value_or(c.ball_start);
      for (std::size_t tk = 0; tk < trackers.size(); ++tk) {
        Rng frng = cooperative_trial_rng(seed, "tracking/filter/" + trackers[tk], t);
        const std::vector<double> e = coop_tracker_errors(c, trackers[tk], r.inputs[in].obs_sigma, first, z[in], frng);
        for (int k = 0; k < r.steps; ++k) add(r.acc[in][tk + 1], k, e[static_cast<std::size_t>(k)]);
      }
    }
  }
  return r;
}

}  // namespace

CoopDirectResult compute_cooperative_direct(const Cooperative001Config& c, const CoopTrials& n, std::uint64_t seed) {
  CoopDirectResult r;
  r.reference_distance = c.reference_distance_or_mean();
  // 1. Headline: every noise model, the configured (default ideal) network, full team.
  for (CoopNoiseModel m : {CoopNoiseModel::Polar, CoopNoiseModel::Cartesian, CoopNoiseModel::RobotPose})
    r.by_model.emplace_back(m, run_path(c, m, c.network, "path/net", n.path, seed));
  // 2. Network: the lossy one, fixes used at their stamps.
  r.lossy = run_path(c, c.noise_model, c.lossy_network, "path/lossy_net", n.path, seed);
  // 3. Error against the number of robots.
  r.robots_vs_error = robots_vs_error(c, n.per_subset, r.reference_distance, seed);
  // 4. Growth-model benchmark.
  r.growth = growth_model(n.growth_model, seed);
  // 5. Tracking on the fixes.
  r.tracking = tracking(c, n.tracking, r.reference_distance, r.model(c.noise_model), r.lossy, seed);
  // The trial drawn in field.png.
  Rng noise = cooperative_trial_rng(seed, "path/noise", 0), netr = cooperative_trial_rng(seed, "path/net", 0);
  r.example = run_trial(c, c.noise_model, r.reference_distance, all_robots(c), c.network, c.fusion_deadline, noise, netr);
  return r;
}

// --- the experiment -------------------------------------------------------------------------------------

int run_cooperative_001(const ExperimentArgs& args, std::ostream& out) {
  const auto t_start = std::chrono::steady_clock::now();
  CoopRun run;
  run.config_file = args.config.empty() ? cooperative_001_default_file() : args.config;
  const Cooperative001Config c = load_cooperative_001(run.config_file);
  run.seed = args.seed;
  run.quick = args.quick;
  run.trials = args.quick ? c.quick_trials : c.trials;
  harness::RunDirectory dir(args.out_dir);
  const CoopDirectResult direct = compute_cooperative_direct(c, run.trials, run.seed);
  // The rendered-image mode: the same path seen through each robot's own camera.
  std::optional<CoopRenderedResult> rendered;
  if (c.rendered) rendered = compute_cooperative_rendered(c, args.quick ? c.rendered->quick_trials : c.rendered->trials, run.seed, &out);
  run.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  write_cooperative_report(c, run, direct, rendered ? &*rendered : nullptr, dir, out);
  return 0;
}

}  // namespace omniloc::experiments
