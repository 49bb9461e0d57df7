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
      bool_param("range_weights", &P::range_weights, "weigh line points by range: (weight_ref^2 + weight_d^2) / (weight_d^2 + r^2) (NuBot)"),
      positive_param("weight_d", &P::weight_d, 100.0, "m", "range weights: the range scale d (NuBot: 2.5 m)"),
      positive_param("weight_ref", &P::weight_ref, 100.0, "m", "range weights: the range whose points weigh 1 (NuBot: 1.5 m)"),
      number_param("tilt_sd", &P::tilt_sd, 0.0, 0.2, "rad", "camera tilt std (roll, pitch) shared by a frame's points, in the match covariance; 0: none"),
      positive_param("camera_height", &P::camera_height, 5.0, "m", "mirror viewpoint above the floor, for tilt_sd"),
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

PointWeights range_weights(const std::vector<Eigen::Vector2d>& pts, const MatchingParams& p) {
  PointWeights w;
  if (!p.range_weights) return w;
  const double d2 = p.weight_d * p.weight_d, num = p.weight_ref * p.weight_ref + d2;
  w.w.reserve(pts.size());
  for (const auto& o : pts) {
    w.w.push_back(num / (d2 + o.squaredNorm()));
    w.total += w.w.back();
  }
  return w;
}

namespace {

// The points as a camera tilted by tau (radians; tau.x() tips the view along the robot's x axis,
// tau.y() along y) would place them: a floor point at range r and unit direction u seen from height
// h moves by (h^2 + r^2) / h per radian of tilt towards u (d(h / tan(a)) / da = -(h^2 + r^2) / h).
std::vector<Eigen::Vector2d> tilted(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& tau, double h) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(pts.size());
  for (const auto& o : pts) {
    const double r = o.norm();
    if (r <= 0) {
      out.push_back(o);
      continue;
    }
    const Eigen::Vector2d u = o / r;
    out.push_back(o + u * (u.dot(tau) * (h * h + r * r) / h));
  }
  return out;
}

}  // namespace

MatchResult rprop_match(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& start, const MatchingParams& p,
                        int max_iterations, std::optional<double> prior_theta, std::vector<double>* trace) {
  const PointWeights pw = range_weights(pts, p);
  const double total = p.range_weights ? pw.total : static_cast<double>(pts.size());
  const auto term = [&](const std::vector<Eigen::Vector2d>& at, const Eigen::Vector3d& x, double c, Eigen::Vector3d* g) {
    return match_data_term(map, at, x, c, g, &pw);
  };
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
    // more iterations and lost cold starts in Matching.ConvergesFromColdStartsOnRandomPoses).
    prev.setZero();
    while (r.iterations < end) {
      Eigen::Vector3d g;
      term(pts, q, c, &g);
      if (trace) trace->push_back(pts.empty() ? 1.0 : term(pts, q, p.c, nullptr) / total);
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
  r.error = pts.empty() ? 1.0 : term(pts, q, p.c, nullptr) / total;
  if (trace) trace->push_back(r.error);
  // Curvature of the data term by central differences of its gradient. Near the optimum
  // e(d) ~ d^2 / c^2, so the Gauss-Newton information of points with noise sigma is H c^2 / (2 sigma^2).
  Eigen::Matrix3d H;
  const Eigen::Vector3d h(0.01, 0.01, 0.005);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d qp = q, qm = q, gp, gm;
    qp[k] += h[k];
    qm[k] -= h[k];
    term(pts, qp, p.c, &gp);
    term(pts, qm, p.c, &gm);
    H.col(k) = (gp - gm) / (2 * h[k]);
  }
  H = 0.5 * (H + H.transpose()).eval();
  const double info_per_curvature = p.c * p.c / (2 * p.point_sigma * p.point_sigma);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H * info_per_curvature);
  Eigen::Vector3d ev = es.eigenvalues();
  // A flat direction (all points on one line) gets a large variance instead of an infinite one.
  for (int k = 0; k < 3; ++k) ev[k] = 1.0 / std::max(ev[k], 1.0);
  r.covariance = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  if (p.tilt_sd > 0 && !pts.empty()) {
    // A tilt moves all points together, so its share of the error does not average out over them:
    // the minimum moves by dq / dtau = -H^-1 d(grad E) / dtau (implicit function theorem), with
    // d(grad E) / dtau by central differences of tilted points. r.covariance is (H s)^-1, s the
    // information per curvature, so H^-1 = s r.covariance (flat directions capped as above).
    const double eps = 1e-3;  // rad: moves a point at 6 m by 5 cm, within the error's quadratic range
    Eigen::Matrix<double, 3, 2> J;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d tau = eps * Eigen::Vector2d::Unit(k);
      Eigen::Vector3d gp, gm;
      term(tilted(pts, tau, p.camera_height), q, p.c, &gp);
      term(tilted(pts, -tau, p.camera_height), q, p.c, &gm);
      J.col(k) = -info_per_curvature * r.covariance * ((gp - gm) / (2 * eps));
    }
    r.covariance += p.tilt_sd * p.tilt_sd * J * J.transpose();
  }
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
