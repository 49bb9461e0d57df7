#include "localization/matching.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "localization/match_data_term.hpp"

namespace omniloc {

const ParamList<MatchingParams>& MatchingParams::params() {
  using P = MatchingParams;
  static const ParamList<P> list = {
      positive_param("c", &P::c, 5.0, "m", "error scale of e(d) = 1 - c^2 / (c^2 + d^2) (Tribots: 250 mm)"),
      positive_param("c_start", &P::c_start, 10.0, "m", "continuation: c halves from c_start down to c (JSON default: 2 c, one smoothing stage)"),
      positive_param("step_xy", &P::step_xy, 2.0, "m", "RPROP initial step in x and y (Tribots: 40 mm)"),
      positive_param("step_theta", &P::step_theta, 1.0, "rad", "RPROP initial step in theta (Tribots: 0.1)"),
      number_param("grow", &P::grow, 1.0, 3.0, "", "RPROP step growth factor (Tribots: 1.2)"),
      number_param("shrink", &P::shrink, 0.05, 1.0, "", "RPROP step shrink factor (Tribots: 0.5)"),
      number_param("step_tol", &P::step_tol, 1e-6, 0.1, "m, rad", "RPROP stops when its steps in x, y and theta are all below this"),
      integer_param("max_iterations", &P::max_iterations, 1, 1000, "cap on RPROP iterations over all stages (Tribots 10-20, NuBot 25)"),
      integer_param("min_points", &P::min_points, 1, 10000, "fewer line points: no match, coast on odometry (NuBot > 15, CAMBADA > 5)"),
      integer_param("max_points", &P::max_points, 3, 100000, "line points evenly subsampled beyond this"),
      number_param("heading_prior", &P::heading_prior, 0.0, 1000.0, "", "weight of (theta - predicted theta)^2 (Tribots: 2.5)"),
      positive_param("point_sigma", &P::point_sigma, 2.0, "m", "line-point noise that turns the error's curvature into a covariance"),
      number_param("cell", &P::cell, 0.005, 0.5, "m", "distance-map cell (Tribots: 50 mm)"),
  };
  return list;
}

Json MatchingParams::schema() {
  const MatchingParams d;
  Json s = params_schema(params(), d);
  s.update(params_schema(filter::OdometryNoiseParams::params(filter::OdometryNoiseParams::Keys::WithRotPerMetre), d.odometry));
  return s;
}

MatchingParams MatchingParams::from_json(JsonReader& r) {
  MatchingParams p;
  for (const char* old : {"iterations", "iterations_few", "many_points"})
    if (r.has(old))
      throw ConfigError(r.child_path(old), json_brief(*r.raw(old)),
                        "no such key (removed): RPROP runs until its steps are below step_tol, at most max_iterations times");
  read_param(r, p, params(), "c");
  p.c_start = 2.0 * p.c;  // one smoothing stage unless set
  read_params(r, p, params());
  p.odometry = filter::OdometryNoiseParams::from_json(r, p.odometry, filter::OdometryNoiseParams::Keys::WithRotPerMetre);
  return p;
}

std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& pts, int n) {
  if (static_cast<int>(pts.size()) <= n) return pts;
  std::vector<Eigen::Vector2d> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) out.push_back(pts[static_cast<std::size_t>(i) * pts.size() / n]);
  return out;
}

double match_error(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& pose, double c) {
  if (pts.empty()) return 1.0;
  return match_data_term(map, pts, {pose.x, pose.y, pose.theta}, c, nullptr) / pts.size();
}

MatchResult rprop_match(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& start, const MatchingParams& p,
                        int max_iterations, std::optional<double> prior_theta, std::vector<double>* trace) {
  Eigen::Vector3d q(start.x, start.y, start.theta);
  Eigen::Vector3d step(p.step_xy, p.step_xy, p.step_theta), prev = Eigen::Vector3d::Zero();
  const Eigen::Vector3d max_step(1.0, 1.0, 0.5), min_step(1e-6, 1e-6, 1e-6);
  MatchResult r;
  r.points = static_cast<int>(pts.size());
  // Continuation: stages with c = c_start, c_start / 2, ... down to c. Each stage runs until its
  // RPROP steps are all below its tolerance (step_tol scaled by c_stage / c: a smoothed stage only
  // brings the pose into the final basin, its own minimum is off the final one by more than that)
  // or until its share of the cap; the final stage gets every iteration the earlier ones left, so
  // at least its own share, however the cap and the number of stages compare.
  int stages = 1;
  if (p.c_start > p.c) stages = static_cast<int>(std::ceil(std::log2(p.c_start / p.c))) + 1;
  const int cap = std::max(1, max_iterations);
  const int share = std::max(1, cap / stages);
  for (int stage = 0; stage < stages && r.iterations < cap; ++stage) {
    const bool last = stage == stages - 1;
    const double c = last ? p.c : std::max(p.c, p.c_start * std::pow(0.5, stage));
    const double tol = p.step_tol * c / p.c;
    const int end = last ? cap : std::min(cap, r.iterations + share);
    // A new error function: the last stage's gradient signs say nothing about this one's. The steps
    // carry over: the minimum moves by less than they have shrunk to (restarting them at step0 cost
    // more iterations and lost cold starts on the test of issue 17).
    prev.setZero();
    while (r.iterations < end) {
      Eigen::Vector3d g;
      match_data_term(map, pts, q, c, &g);
      if (trace) trace->push_back(pts.empty() ? 1.0 : match_data_term(map, pts, q, p.c, nullptr) / pts.size());
      if (prior_theta && p.heading_prior > 0) g.z() += 2.0 * p.heading_prior * angle_diff(q.z(), *prior_theta);
      for (int k = 0; k < 3; ++k) {
        // iRPROP-: on a sign change shrink the step and skip this update.
        if (g[k] * prev[k] > 0) step[k] = std::min(step[k] * p.grow, max_step[k]);
        else if (g[k] * prev[k] < 0) {
          step[k] = std::max(step[k] * p.shrink, min_step[k]);
          g[k] = 0;
        }
        if (g[k] > 0) q[k] -= step[k];
        else if (g[k] < 0) q[k] += step[k];
        prev[k] = g[k];
      }
      ++r.iterations;
      if (step.maxCoeff() < tol) {
        if (last) r.converged = true;
        break;
      }
    }
  }
  r.pose = Pose2(q.x(), q.y(), q.z());
  r.error = pts.empty() ? 1.0 : match_data_term(map, pts, q, p.c, nullptr) / pts.size();
  if (trace) trace->push_back(r.error);
  // Curvature of the data term by central differences of its gradient. Near the optimum
  // e(d) ~ d^2 / c^2, so the Gauss-Newton information of points with noise sigma is H c^2 / (2 sigma^2).
  Eigen::Matrix3d H;
  const Eigen::Vector3d h(0.01, 0.01, 0.005);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d qp = q, qm = q, gp, gm;
    qp[k] += h[k];
    qm[k] -= h[k];
    match_data_term(map, pts, qp, p.c, &gp);
    match_data_term(map, pts, qm, p.c, &gm);
    H.col(k) = (gp - gm) / (2 * h[k]);
  }
  H = 0.5 * (H + H.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H * (p.c * p.c / (2 * p.point_sigma * p.point_sigma)));
  Eigen::Vector3d ev = es.eigenvalues();
  // A flat direction (all points on one line) gets a large variance instead of an infinite one.
  for (int k = 0; k < 3; ++k) ev[k] = 1.0 / std::max(ev[k], 1.0);
  r.covariance = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  return r;
}

MatchingLocalizer::MatchingLocalizer(const Field& field, const MatchingParams& p, const std::string& cache_dir)
    : p_(p), map_(field, p.cell, cache_dir) {}

void MatchingLocalizer::reset(const std::optional<Pose2>& start) {
  started_ = start.has_value();
  kf_.reset(start.value_or(Pose2()), Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.02 * 0.02).asDiagonal());
}

Estimate MatchingLocalizer::track(const Observations& obs, const Odometry& odometry) {
  kf_.predict(odometry.delta, p_.odometry);
  Estimate e;
  const std::vector<Eigen::Vector2d> pts = subsample(obs.line_points, p_.max_points);
  e.extra["points"] = static_cast<double>(pts.size());
  if (!obs.camera_ok || static_cast<int>(pts.size()) < p_.min_points) {
    e.mode = LocalizerMode::kCoasting;  // no usable vision: odometry only, no jump
    e.pose = kf_.pose();
    e.covariance = kf_.covariance();
    e.valid = started_;
    e.match_error = 1.0;  // the worst possible mean error: nothing matched
    return e;
  }
  // RPROP's first steps: one standard deviation of the prediction, at most Tribots' steps (a fresh
  // reset's 5 cm) and at least 4 step_tol. Tribots' 0.1 rad first step throws a prediction good to
  // 0.01 rad off by 0.09 rad, and halving it back below step_tol takes about a dozen iterations
  // (23 instead of 14 on BM_MatchingUpdate/200).
  MatchingParams p = p_;
  const Eigen::Matrix3d& P = kf_.covariance();
  p.step_xy = std::clamp(std::sqrt(std::max(P(0, 0), P(1, 1))), 4 * p_.step_tol, std::max(p_.step_xy, 4 * p_.step_tol));
  p.step_theta = std::clamp(std::sqrt(P(2, 2)), 4 * p_.step_tol, std::max(p_.step_theta, 4 * p_.step_tol));
  const MatchResult m = rprop_match(map_, pts, kf_.pose(), p, p.max_iterations, kf_.pose().theta);
  kf_.update(m.pose, m.covariance);
  e.pose = kf_.pose();
  e.covariance = kf_.covariance();
  e.valid = started_;
  e.mode = LocalizerMode::kTracking;
  e.match_error = m.error;
  e.extra["iterations"] = m.iterations;
  e.extra["match_sd_xy"] = std::sqrt(0.5 * (m.covariance(0, 0) + m.covariance(1, 1)));
  return e;
}

Estimate MatchingLocalizer::update(const Observations& obs, const Odometry& odometry, std::optional<double>) { return track(obs, odometry); }

}  // namespace omniloc
