#include "localization/landmarks/landmark_fix.hpp"
#include "localization/landmarks/triple_fix.hpp"

#include <cmath>
#include <utility>

#include <Eigen/LU>

namespace omniloc::landmarks {

double landmark_scale(std::span<const BearingObs> obs) {
  double best = 0.0;
  for (std::size_t i = 0; i < obs.size(); ++i)
    for (std::size_t j = i + 1; j < obs.size(); ++j) best = std::max(best, (obs[i].landmark - obs[j].landmark).squaredNorm());
  return std::sqrt(best);
}

std::string check_input(std::span<const BearingObs> obs) {
  if (obs.size() < 3) return "fewer than 3 landmarks (got " + std::to_string(obs.size()) + ")";
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (!std::isfinite(obs[i].landmark.x()) || !std::isfinite(obs[i].landmark.y()))
      return "non-finite landmark position (observation " + std::to_string(i) + ")";
    if (!std::isfinite(obs[i].bearing)) return "non-finite bearing (observation " + std::to_string(i) + ")";
  }
  // The same landmark twice; remember the farthest pair for the collinearity test.
  std::size_t a = 0, b = 1;
  double far2 = -1.0;
  for (std::size_t i = 0; i < obs.size(); ++i)
    for (std::size_t j = i + 1; j < obs.size(); ++j) {
      const double d2 = (obs[i].landmark - obs[j].landmark).squaredNorm();
      if (d2 < kSameLandmark * kSameLandmark)
        return "the same landmark given twice (observations " + std::to_string(i) + " and " + std::to_string(j) + ")";
      if (d2 > far2) {
        far2 = d2;
        a = i;
        b = j;
      }
    }
  // Collinear: every landmark within kSingularTol * scale of the line through the farthest pair.
  // (With collinear landmarks the "circle through the landmarks" is that line; a robot off the line
  // could still be placed, but the project's contract refuses this input outright.)
  const Eigen::Vector2d u = obs[b].landmark - obs[a].landmark;
  double off = 0.0;
  for (const auto& o : obs) {
    const Eigen::Vector2d v = o.landmark - obs[a].landmark;
    off = std::max(off, std::fabs(u.x() * v.y() - u.y() * v.x()));
  }
  if (off <= kSingularTol * far2) return "landmarks are collinear";
  return "";
}

std::string check_triple(std::span<const BearingObs> obs) {
  if (obs.size() > 3)
    return "closed-form solver takes exactly 3 landmarks (got " + std::to_string(obs.size()) +
           "); use least_squares_bearings for more";
  return check_input(obs);
}

bool heading_from_bearings(std::span<const BearingObs> obs, std::span<const Eigen::Vector2d> dirs,
                           const Eigen::Vector2d& position, double& theta) {
  // Each landmark gives a heading estimate: direction to the landmark (world) minus its bearing.
  // As a vector: the world offset L - P rotated by -bearing; summing these vectors is the
  // distance-weighted circular mean, and needs no per-landmark atan2.
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const Eigen::Vector2d d = obs[i].landmark - position;
    const double c = dirs.empty() ? std::cos(obs[i].bearing) : dirs[i].x();
    const double s = dirs.empty() ? std::sin(obs[i].bearing) : dirs[i].y();
    sum += Eigen::Vector2d(c * d.x() + s * d.y(), c * d.y() - s * d.x());
  }
  if (!(sum.squaredNorm() > 0.0) || !std::isfinite(sum.x()) || !std::isfinite(sum.y())) return false;
  theta = std::atan2(sum.y(), sum.x());
  return true;
}

double bearing_reliability(std::span<const BearingObs> obs, const Eigen::Vector2d& position) {
  // Bearing_i = atan2(dy, dx) - theta with (dx, dy) = L_i - P:
  // d/dx = dy / rho^2, d/dy = -dx / rho^2, d/dtheta = -1.
  const auto row = [&](std::size_t i, double& jx, double& jy) {
    const Eigen::Vector2d d = obs[i].landmark - position;
    const double r2 = d.squaredNorm();
    if (!(r2 > 0.0)) return false;
    jx = d.y() / r2;
    jy = -d.x() / r2;
    return true;
  };
  if (obs.size() == 3) {
    // Square Jacobian: its inverse directly (not J^T J, which would square its condition number and
    // blur the singular set), in closed form (detail::triple_reliability).
    Eigen::Vector2d d[3];
    double r2[3];
    for (std::size_t i = 0; i < 3; ++i) {
      d[i] = obs[i].landmark - position;
      r2[i] = d[i].squaredNorm();
      if (!(r2[i] > 0.0)) return 0.0;
    }
    return detail::triple_reliability(d, r2);
  }
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < obs.size(); ++i) {
    double jx = 0, jy = 0;
    if (!row(i, jx, jy)) return 0.0;
    const Eigen::Vector3d j(jx, jy, -1.0);
    A += j * j.transpose();
  }
  const double det = A.determinant();
  if (!(det > 0.0) || !std::isfinite(det)) return 0.0;
  const double trace = A.inverse().topLeftCorner<2, 2>().trace();
  if (!(trace > 0.0) || !std::isfinite(trace)) return 0.0;
  return 1.0 / std::sqrt(trace);
}

Fix finish_fix(std::span<const BearingObs> obs, std::span<const Eigen::Vector2d> dirs, const Eigen::Vector2d& position,
               double scale) {
  if (obs.size() == 3) {
    double c[3], s[3];
    for (std::size_t i = 0; i < 3; ++i) {
      c[i] = dirs.empty() ? std::cos(obs[i].bearing) : dirs[i].x();
      s[i] = dirs.empty() ? std::sin(obs[i].bearing) : dirs[i].y();
    }
    return detail::finish_triple(obs, c, s, 0.0, position, scale * scale);
  }
  if (!std::isfinite(position.x()) || !std::isfinite(position.y()))
    return no_fix("numerical failure: non-finite position (singular geometry)");
  for (const auto& o : obs)
    if ((o.landmark - position).squaredNorm() < kSameLandmark * kSameLandmark)
      return no_fix("robot at a landmark (its bearing is undefined; a point of the singular circle)");
  double theta = 0.0;
  if (!heading_from_bearings(obs, dirs, position, theta)) return no_fix("heading undefined at the computed position");
  const double rel = bearing_reliability(obs, position);
  if (!(rel * scale >= kSingularTol))
    return no_fix(obs.size() == 3 ? "robot on the circle through the three landmarks (singular geometry)"
                                  : "singular geometry (bearings do not determine the pose)");
  Fix f;
  f.ok = true;
  f.pose = Pose2(position.x(), position.y(), theta);
  f.reliability = rel;
  return f;
}

}  // namespace omniloc::landmarks
