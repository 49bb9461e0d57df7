// Cooperative ball fix in Hough space, paper 001 section 4 (eqs. (8)-(11)). See hough_ball.hpp.
#include "localization/cooperative/hough_ball.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

namespace omniloc {

namespace {

bool finite(const Eigen::Vector2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

double weight_for(double distance, const HoughBallConfig& cfg) {
  if (cfg.weighting == BallWeighting::Equal) return 1.0;
  const double floor = cfg.min_distance > 0.0 ? cfg.min_distance : 0.05;
  return 1.0 / std::max(distance, floor);
}

}  // namespace

HoughLine hough_line(const BallLine& line, const HoughBallConfig& cfg) {
  HoughLine h;
  const Eigen::Vector2d d = line.ball_estimate - line.robot;
  h.distance = d.norm();
  h.weight = weight_for(h.distance, cfg);
  if (!(h.distance >= cfg.direction_epsilon)) {
    // No direction: the caller uses the sighting as a point. theta = 0 describes the vertical line
    // through the estimate; the perpendicular one is added by hough_ball_fix.
    h.point_constraint = true;
    h.theta = 0.0;
    h.rho = line.ball_estimate.x();
    return h;
  }
  // Unit normal of the line robot -> ball: the direction rotated by +90 degrees.
  const Eigen::Vector2d n(-d.y() / h.distance, d.x() / h.distance);
  h.theta = std::atan2(n.y(), n.x());
  h.rho = n.dot(line.robot);  // paper eq. (8): rho = x cos(theta) + y sin(theta) for any point on the line
  return h;
}

const char* to_string(BallFix::Status s) {
  switch (s) {
    case BallFix::Status::Ok: return "ok";
    case BallFix::Status::SingleRobot: return "single_robot";
    case BallFix::Status::NoObservation: return "no_observation";
    case BallFix::Status::Degenerate: return "degenerate";
  }
  return "unknown";
}

BallFix hough_ball_fix(const std::vector<BallLine>& lines, const HoughBallConfig& cfg) {
  BallFix fix;
  std::ostringstream notes;

  // Usable sightings: finite, and not older than max_age behind the newest finite stamp.
  std::vector<const BallLine*> usable;
  int non_finite = 0, stale = 0;
  double newest = -1e300;
  for (const BallLine& l : lines)
    if (finite(l.robot) && finite(l.ball_estimate) && std::isfinite(l.stamp)) newest = std::max(newest, l.stamp);
  for (const BallLine& l : lines) {
    if (!(finite(l.robot) && finite(l.ball_estimate) && std::isfinite(l.stamp))) {
      ++non_finite;
      continue;
    }
    if (newest - l.stamp > cfg.max_age) {
      ++stale;
      continue;
    }
    usable.push_back(&l);
  }
  if (non_finite > 0) notes << non_finite << " non-finite sighting(s) skipped; ";
  if (stale > 0) notes << stale << " sighting(s) older than " << cfg.max_age << " s skipped; ";

  fix.used = static_cast<int>(usable.size());
  if (usable.empty()) {
    fix.status = BallFix::Status::NoObservation;
    notes << "no robot sees the ball";
    fix.reason = notes.str();
    return fix;
  }
  if (usable.size() == 1) {
    fix.status = BallFix::Status::SingleRobot;
    fix.position = usable.front()->ball_estimate;
    notes << "one robot only: its own bearing/distance estimate (no line intersection)";
    fix.reason = notes.str();
    return fix;
  }

  // Normal equations of J (eq. (11)): M [X Y]^T = b with M = sum K n n^T, b = sum K rho n,
  // n = (cos theta, sin theta).
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double weight_sum = 0.0;
  int clamped = 0, points = 0;
  for (const BallLine* l : usable) {
    const HoughLine h = hough_line(*l, cfg);
    if (cfg.weighting == BallWeighting::InverseDistance && h.distance < cfg.min_distance) ++clamped;
    mean += h.weight * l->ball_estimate;
    weight_sum += h.weight;
    if (h.point_constraint) {
      // Two perpendicular lines through the estimate: K (p - e)^T (p - e).
      ++points;
      M += h.weight * Eigen::Matrix2d::Identity();
      b += h.weight * l->ball_estimate;
      continue;
    }
    const Eigen::Vector2d n(std::cos(h.theta), std::sin(h.theta));
    M += h.weight * n * n.transpose();
    b += h.weight * h.rho * n;
  }
  mean /= weight_sum;
  if (clamped > 0)
    notes << clamped << " robot-ball distance(s) below " << cfg.min_distance << " m clamped to it for the weight; ";
  if (points > 0) notes << points << " sighting(s) at the robot's own position used as point constraints; ";

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues()(0), lmax = eig.eigenvalues()(1);
  const double rcond = lmax > 0.0 ? lmin / lmax : 0.0;
  if (!(rcond >= cfg.min_reciprocal_condition)) {
    fix.status = BallFix::Status::Degenerate;
    fix.position = mean;
    notes << "lines nearly parallel (robots collinear with the ball): normal-matrix reciprocal condition "
          << rcond << " < " << cfg.min_reciprocal_condition
          << "; position is the weighted mean of the robots' own estimates";
    fix.reason = notes.str();
    return fix;
  }
  const Eigen::Vector2d p = M.ldlt().solve(b);
  if (!finite(p)) {  // cannot happen with rcond above a positive threshold; kept as a guard
    fix.status = BallFix::Status::Degenerate;
    fix.position = mean;
    notes << "solve gave a non-finite result; position is the weighted mean of the robots' own estimates";
    fix.reason = notes.str();
    return fix;
  }
  fix.status = BallFix::Status::Ok;
  fix.position = p;
  std::string r = notes.str();
  if (r.size() >= 2 && r.substr(r.size() - 2) == "; ") r.resize(r.size() - 2);
  fix.reason = r;
  return fix;
}

}  // namespace omniloc
