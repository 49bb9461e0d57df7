#include "localization/landmarks/landmark_solvers.hpp"

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "core/angles.hpp"

namespace omniloc::landmarks {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Left perpendicular (rotation by +90 degrees).
Eigen::Vector2d perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

/// Centre of the circle through A, B and a robot R that sees the chord A -> B under the signed
/// (anticlockwise) angle theta = bearing(B) - bearing(A), given as (cos theta, sin theta); sin theta != 0.
/// Inscribed-angle theorem: the centre is on the chord's perpendicular bisector, at cot(theta) / 2
/// chord lengths to the left of A -> B: O = (A + B) / 2 + cot(theta) / 2 * perp(B - A).
Eigen::Vector2d inscribed_centre(const Eigen::Vector2d& A, const Eigen::Vector2d& B, double c, double s) {
  return 0.5 * (A + B) + (0.5 * c / s) * perp(B - A);
}

std::array<Eigen::Vector2d, 3> bearing_dirs(std::span<const BearingObs> obs) {
  std::array<Eigen::Vector2d, 3> d;
  for (std::size_t i = 0; i < 3; ++i) d[i] = {std::cos(obs[i].bearing), std::sin(obs[i].bearing)};
  return d;
}

/// (cos, sin) of bearing_j - bearing_i from the bearings' unit vectors.
Eigen::Vector2d diff_dir(const Eigen::Vector2d& di, const Eigen::Vector2d& dj) {
  return {di.dot(dj), cross(di, dj)};
}

std::string line_reason(int i, int j) {
  return "robot on the line through landmarks " + std::to_string(i) + " and " + std::to_string(j) +
         " (bearing difference 0 or pi)";
}

const char* const kOnCircle = "robot on the circle through the three landmarks";

}  // namespace

// ---------------------------------------------------------------------------------------------
Fix three_point_004(std::span<const BearingObs> obs) {
  if (auto r = check_triple(obs); !r.empty()) return no_fix(std::move(r));
  const Eigen::Vector2d& P1 = obs[0].landmark;
  const Eigen::Vector2d& P2 = obs[1].landmark;
  const Eigen::Vector2d& P3 = obs[2].landmark;
  const double phi01 = obs[0].bearing, phi02 = obs[1].bearing, phi03 = obs[2].bearing;

  // Eqs. (11)-(14): distances and directions from P2 to P1 and P3 (tan^-1 taken as atan2 so the
  // direction keeps its quadrant).
  const double d21 = (P1 - P2).norm();
  const double d23 = (P3 - P2).norm();
  const double phi21 = std::atan2(P1.y() - P2.y(), P1.x() - P2.x());
  const double phi23 = std::atan2(P3.y() - P2.y(), P3.x() - P2.x());
  // Eqs. (15)-(18), normalised to [0, 2 pi) as eq. (20) asks.
  const double a102 = wrap_angle_positive(phi02 - phi01);
  const double a203 = wrap_angle_positive(phi03 - phi02);
  const double a321 = wrap_angle_positive(phi21 - phi23);
  const double beta = wrap_angle_positive(kTwoPi - a102 - a203 - a321);
  const double s102 = std::sin(a102), s203 = std::sin(a203);
  if (std::fabs(s102) < kSingularTol) return no_fix(line_reason(0, 1));
  if (std::fabs(s203) < kSingularTol) return no_fix(line_reason(1, 2));
  // Eq. (19). It comes from the law of sines in triangles P0P1P2 and P0P2P3 (both giving |P0P2|):
  // tan(alpha210) = sin(beta) / (k + cos(beta)), k = d21 sin(alpha203) / (d23 sin(alpha102)).
  // A one-argument tan^-1 fixes alpha210 only modulo pi and the paper's normalisation to [0, 2 pi)
  // does not choose the branch; we take the branch with |P0P2| = d21 sin(alpha210) / sin(alpha102) > 0,
  // i.e. sin(alpha210) of the sign of sin(alpha102) (paper silent; our choice).
  const double k = d21 * s203 / (d23 * s102);
  const double num = std::sin(beta), den = k + std::cos(beta);
  // On the circle through P1, P2, P3 the quadrilateral P0P1P2P3 is cyclic: num = den = 0.
  if (std::hypot(num, den) < kSingularTol * std::max(1.0, std::fabs(k))) return no_fix(kOnCircle);
  const double sg = s102 > 0.0 ? 1.0 : -1.0;
  const double a210 = wrap_angle_positive(std::atan2(sg * num, sg * den));
  // Eq. (21): P0 = P1 + |P1P0| (cos, sin)(pi + phi21 + alpha210), |P1P0| by the law of sines.
  const double r10 = d21 * std::sin(kPi - a102 - a210) / s102;
  const double dir = kPi + phi21 + a210;
  const Eigen::Vector2d P0 = P1 + r10 * Eigen::Vector2d(std::cos(dir), std::sin(dir));
  // Eq. (22) gives the heading from P1 alone: phi0 = phi21 + alpha210 - phi01 (the direction P0 -> P1
  // minus its bearing). finish_fix computes the same quantity averaged over the three landmarks.
  return finish_fix(obs, {}, P0, landmark_scale(obs));
}

// ---------------------------------------------------------------------------------------------
Fix two_circle_004(std::span<const BearingObs> obs) {
  if (auto r = check_triple(obs); !r.empty()) return no_fix(std::move(r));
  const Eigen::Vector2d& D1L = obs[0].landmark;
  const Eigen::Vector2d& D1R = obs[1].landmark;
  const Eigen::Vector2d& D2L = obs[2].landmark;
  // Subtended angles at R, signed anticlockwise (the paper's theta1, theta2; it has D1_L to the
  // left of D1_R, so theta1 > 0 there).
  const double th1 = wrap_angle(obs[0].bearing - obs[1].bearing);
  const double th2 = wrap_angle(obs[1].bearing - obs[2].bearing);
  const double s1 = std::sin(th1), s2 = std::sin(th2);
  if (std::fabs(s1) < kSingularTol) return no_fix(line_reason(0, 1));
  if (std::fabs(s2) < kSingularTol) return no_fix(line_reason(1, 2));
  // Eqs. (1)-(4): O = D + R(90deg - theta) (V / 2) / cos(90deg - theta); R(.) the rotation matrix.
  // The triangle D, O, chord midpoint has its angle 90deg - theta at D (central angle 2 theta).
  const auto centre = [](const Eigen::Vector2d& V, const Eigen::Vector2d& D, double th) {
    const double a = kPi / 2 - th;
    const double ca = std::cos(a), sa = std::sin(a);
    const Eigen::Vector2d h = 0.5 * V;
    return Eigen::Vector2d(D + Eigen::Vector2d(ca * h.x() - sa * h.y(), sa * h.x() + ca * h.y()) / ca);
  };
  const Eigen::Vector2d V_D1 = D1L - D1R;          // (1)
  const Eigen::Vector2d O1 = centre(V_D1, D1R, th1);  // (2)
  const Eigen::Vector2d V_D2 = D1R - D2L;          // (3)
  const Eigen::Vector2d O2 = centre(V_D2, D2L, th2);  // (4)
  const Eigen::Vector2d V_OD2 = D1R - O2;          // (5)
  const Eigen::Vector2d V_O = O1 - O2;             // (6)
  // Both circles pass through D1_R; they coincide when R is on the circle through all three.
  const double radius = std::max(V_OD2.norm(), (D1R - O1).norm());
  if (!(V_O.norm() >= kSingularTol * radius)) return no_fix(kOnCircle);
  // Eq. (7): theta_OD = angle between V_OD2 and V_O. acos of the normalised dot product loses half
  // the digits near 0 and pi; atan2(|cross|, dot) is the same angle, well conditioned.
  const double cr = cross(V_O, V_OD2);
  const double th_od = std::atan2(std::fabs(cr), V_O.dot(V_OD2));
  // Eqs. (8)-(9): R = R(+-2 theta_OD) V_OD2 + O2, the mirror image of D1_R in the line O2O1. The
  // paper writes +2 theta_OD in (8) and -2 theta_OD in (9); the right sign depends on the side of
  // O2O1 that D1_R lies on: rotate V_OD2 back across V_O (clockwise when V_OD2 is anticlockwise of V_O).
  const double rot = cr > 0.0 ? -2.0 * th_od : 2.0 * th_od;
  const double cr2 = std::cos(rot), sr2 = std::sin(rot);
  const Eigen::Vector2d R(cr2 * V_OD2.x() - sr2 * V_OD2.y() + O2.x(), sr2 * V_OD2.x() + cr2 * V_OD2.y() + O2.y());
  return finish_fix(obs, {}, R, landmark_scale(obs));
}

// ---------------------------------------------------------------------------------------------
Fix circle_intersection_003(std::span<const BearingObs> obs) {
  if (auto r = check_triple(obs); !r.empty()) return no_fix(std::move(r));
  const auto dirs = bearing_dirs(obs);
  // (cos, sin) of the angle subtended at the robot by each pair, e[i][j] = bearing_j - bearing_i.
  std::array<std::array<Eigen::Vector2d, 3>, 3> e;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) e[i][j] = diff_dir(dirs[i], dirs[j]);
  // Shared landmark k: the two circles are (L_k, L_i, R) and (L_k, L_j, R). Choose k so that both
  // subtended angles are farthest from 0 and pi (a circle's centre goes to infinity as its angle
  // does); then only the circle through all three landmarks is singular. Paper silent; our choice.
  std::size_t k = 0;
  double best = -1.0;
  for (std::size_t c = 0; c < 3; ++c) {
    const std::size_t i = (c + 1) % 3, j = (c + 2) % 3;
    const double q = std::min(std::fabs(e[c][i].y()), std::fabs(e[c][j].y()));
    if (q > best) {
      best = q;
      k = c;
    }
  }
  const std::size_t i = (k + 1) % 3, j = (k + 2) % 3;
  if (best < kSingularTol) return no_fix("robot on the lines through two landmark pairs");
  const Eigen::Vector2d& Lk = obs[k].landmark;
  const Eigen::Vector2d Oa = inscribed_centre(Lk, obs[i].landmark, e[k][i].x(), e[k][i].y());
  const Eigen::Vector2d Ob = inscribed_centre(Lk, obs[j].landmark, e[k][j].x(), e[k][j].y());
  // The common chord L_k R is perpendicular to the line of centres: R is the mirror of L_k in it.
  const Eigen::Vector2d u = Ob - Oa;
  const double radius = std::max((Lk - Oa).norm(), (Lk - Ob).norm());
  if (!(u.norm() >= kSingularTol * radius)) return no_fix(kOnCircle);
  const Eigen::Vector2d foot = Oa + ((Lk - Oa).dot(u) / u.squaredNorm()) * u;
  const Eigen::Vector2d R = 2.0 * foot - Lk;
  return finish_fix(obs, dirs, R, landmark_scale(obs));
}

// ---------------------------------------------------------------------------------------------
namespace {
/// cot from (cos, sin); an infinite cotangent (bearing difference 0 or pi: the robot on the line
/// through two landmarks) becomes +-kCotMax, so the formulas stay finite and the other two circles
/// carry the solution. The value is our choice. total_like lets only T31 get this large, and there
/// the position is a ratio of two terms linear in T31, so the clamp moves it by ~F / kCotMax, with F
/// growing as range^2 / baseline: measured 8e-10 m at 1e12 and 8e-12 m at 1e14 for robots up to
/// ~40 m away on the lines through two landmarks (tests/landmarks_test.cpp). |sin| above 1 / kCotMax
/// = 1e-14 keeps the cotangent's relative error (sin's rounding is ~1e-16) below 1e-2, which moves
/// the position by ~1e-2 F / kCotMax ~ 1e-13 m.
constexpr double kCotMax = 1e14;
double cot_safe(double c, double s) {
  if (std::fabs(s) * kCotMax > std::fabs(c)) return c / s;
  return std::signbit(s) != std::signbit(c) ? -kCotMax : kCotMax;
}
}  // namespace

Fix total_like(std::span<const BearingObs> obs) {
  if (auto r = check_triple(obs); !r.empty()) return no_fix(std::move(r));
  const auto dirs0 = bearing_dirs(obs);
  // ToTal (Pierlot, Van Droogenbroeck, "A New Three Object Triangulation Algorithm for Mobile Robot
  // Positioning", IEEE T-RO 30(3), 2014), formulated here from its equations; our own code.
  // x12..y31 are twice the centres of the circles (B1, B2, R), (B2, B3, R), (B3, B1, R) relative
  // to B2, k31 is the power-like term of the third circle, and
  //   D = (x12 - x23)(y23 - y31) - (y12 - y23)(x23 - x31),  R = B2 + k31 (y12 - y23, x23 - x12) / D.
  // D and the numerator are linear in T31 = cot(alpha31), but c12 and c23 enter D twice (both
  // factors): a clamped, huge T12 or T23 makes D the difference of two products of size T^2 whose
  // difference is of size T, and the cancellation cost up to 4 mm on the line through the second
  // and third landmarks (issue 17). As in ToTal, only T31 may be infinite: the landmarks are
  // renumbered cyclically (which keeps every signed angle) so that the pair whose bearing
  // difference is nearest 0 or pi is (3, 1). The robot is on at most one of the three lines
  // (two meet only at a landmark, refused by check_triple), so T12 and T23 stay finite and of
  // moderate size, and the clamped T31 = +-kCotMax moves R by ~1e-11 m at most (see cot_safe).
  std::array<std::size_t, 3> idx{0, 1, 2};
  {
    const double s01 = std::fabs(cross(dirs0[0], dirs0[1]));
    const double s12 = std::fabs(cross(dirs0[1], dirs0[2]));
    const double s20 = std::fabs(cross(dirs0[2], dirs0[0]));
    if (s01 < s12 && s01 < s20) idx = {1, 2, 0};       // pair (0, 1) becomes (3, 1)
    else if (s12 < s20 && s12 <= s01) idx = {2, 0, 1};  // pair (1, 2) becomes (3, 1)
  }
  const Eigen::Vector2d& B1 = obs[idx[0]].landmark;
  const Eigen::Vector2d& B2 = obs[idx[1]].landmark;
  const Eigen::Vector2d& B3 = obs[idx[2]].landmark;
  const Eigen::Vector2d &d1 = dirs0[idx[0]], &d2 = dirs0[idx[1]], &d3 = dirs0[idx[2]];
  // Landmarks relative to the second one.
  const Eigen::Vector2d p1 = B1 - B2;
  const Eigen::Vector2d p3 = B3 - B2;
  // Cotangents of the bearing differences (angles subtended at the robot by the pairs 1-2, 2-3, 3-1).
  const Eigen::Vector2d e12 = diff_dir(d1, d2);
  const Eigen::Vector2d e23 = diff_dir(d2, d3);
  const Eigen::Vector2d e31 = diff_dir(d3, d1);
  const double T12 = cot_safe(e12.x(), e12.y());
  const double T23 = cot_safe(e23.x(), e23.y());
  const double T31 = cot_safe(e31.x(), e31.y());  // the only one that can be clamped
  // Modified centres: twice the centres of the circles (B1, B2, R), (B2, B3, R), (B3, B1, R),
  // relative to B2 (inscribed-angle theorem, as in inscribed_centre).
  const Eigen::Vector2d c12(p1.x() + T12 * p1.y(), p1.y() - T12 * p1.x());
  const Eigen::Vector2d c23(p3.x() - T23 * p3.y(), p3.y() + T23 * p3.x());
  const Eigen::Vector2d c31((p3.x() + p1.x()) + T31 * (p3.y() - p1.y()), (p3.y() + p1.y()) - T31 * (p3.x() - p1.x()));
  // R (relative to B2) lies on the first two circles, both through the origin: R.c12 = R.c23 = |R|^2,
  // and on the third: R.(c23 - c31) = -k31. Hence R = k31 * (y12 - y23, x23 - x12) / D.
  const double k31 = p1.x() * p3.x() + p1.y() * p3.y() + T31 * (p1.x() * p3.y() - p3.x() * p1.y());
  const double D = (c12.x() - c23.x()) * (c23.y() - c31.y()) - (c12.y() - c23.y()) * (c23.x() - c31.x());
  // D = 0 when the three centres coincide: the robot on the circle through the landmarks. D is the
  // sum of the cross products of the centres; compared with the size of those products it falls
  // quadratically with the distance to the circle (each centre moves linearly towards the common
  // one). Threshold 1e-14: refused within ~1e-7 scale of the circle (~1e-6 m for landmarks 10 m
  // apart), two decades above the ~1e-16 rounding floor exactly on it.
  const double dnorm = c12.norm() * c23.norm() + c23.norm() * c31.norm() + c31.norm() * c12.norm();
  if (!(std::fabs(D) > 1e-14 * dnorm)) return no_fix(kOnCircle);
  const double invD = 1.0 / D;  // the single division
  const Eigen::Vector2d R(B2.x() + k31 * (c12.y() - c23.y()) * invD, B2.y() + k31 * (c23.x() - c12.x()) * invD);
  return finish_fix(obs, dirs0, R, landmark_scale(obs));
}

// ---------------------------------------------------------------------------------------------
Fix least_squares_bearings(std::span<const BearingObs> obs, const LeastSquaresOptions& opt) {
  if (auto r = check_input(obs); !r.empty()) return no_fix(std::move(r));
  const std::size_t n = obs.size();
  const double scale = landmark_scale(obs);

  // Initial fix: total_like on the best-spread triple (largest reliability).
  Fix init = no_fix("no landmark triple gives a fix");
  std::string last_reason;
  const auto try_triple = [&](std::size_t a, std::size_t b, std::size_t c) {
    const std::array<BearingObs, 3> t{obs[a], obs[b], obs[c]};
    Fix f = total_like(t);
    if (f.ok && f.reliability > init.reliability) init = std::move(f);
    else if (!f.ok) last_reason = f.reason;
  };
  if (n <= 10) {
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = a + 1; b < n; ++b)
        for (std::size_t c = b + 1; c < n; ++c) try_triple(a, b, c);
  } else {
    for (std::size_t a = 0; a < n; ++a) try_triple(a, (a + n / 3) % n, (a + 2 * n / 3) % n);
  }
  if (!init.ok) return no_fix("no landmark triple gives an initial fix (last: " + last_reason + ")");

  // Gauss-Newton on x = (x, y, theta); residual r_i = wrap(atan2(L_i - P) - theta - bearing_i).
  Eigen::Vector3d x(init.pose.x, init.pose.y, init.pose.theta);
  const double min_r2 = (kSingularTol * scale) * (kSingularTol * scale);
  const auto cost = [&](const Eigen::Vector3d& s, double& out) {
    double sum = 0.0;
    for (const auto& o : obs) {
      const Eigen::Vector2d d = o.landmark - s.head<2>();
      if (!(d.squaredNorm() > min_r2)) return false;
      const double r = wrap_angle(std::atan2(d.y(), d.x()) - s.z() - o.bearing);
      sum += r * r;
    }
    out = sum;
    return std::isfinite(sum);
  };
  double f0 = 0.0;
  if (!cost(x, f0)) return no_fix("Gauss-Newton: initial fix on a landmark");
  for (int it = 0; it < opt.max_iterations; ++it) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const auto& o : obs) {
      const Eigen::Vector2d d = o.landmark - x.head<2>();
      const double r2 = d.squaredNorm();
      const double r = wrap_angle(std::atan2(d.y(), d.x()) - x.z() - o.bearing);
      const Eigen::Vector3d j(d.y() / r2, -d.x() / r2, -1.0);
      A += j * j.transpose();
      g += j * r;
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.rcond() > 1e-14))
      return no_fix("Gauss-Newton: singular normal equations");
    const Eigen::Vector3d step = ldlt.solve(-g);
    if (!step.allFinite()) return no_fix("Gauss-Newton: non-finite step");
    // Converged: a small step, or one whose predicted cost reduction (1/2 step^T A step for
    // Gauss-Newton) is lost in the cost's rounding (the floor the residuals' atan2 leaves).
    const bool small_step = step.head<2>().norm() <= opt.step_tol_xy && std::fabs(step.z()) <= opt.step_tol_theta;
    const bool no_gain = 0.5 * step.dot(A * step) <= opt.rel_cost_tol * f0;
    if (small_step || no_gain) {
      x += step;
      Fix f = finish_fix(obs, {}, x.head<2>(), scale);
      if (!f.ok) return f;
      f.pose = Pose2(x.x(), x.y(), x.z());  // the jointly estimated heading
      return f;
    }
    // Step halving until the cost goes down.
    double t = 1.0, f1 = 0.0;
    bool accepted = false;
    for (int h = 0; h <= opt.max_halvings; ++h, t *= 0.5) {
      const Eigen::Vector3d xn = x + t * step;
      if (cost(xn, f1) && f1 <= f0) {
        x = xn;
        f0 = f1;
        accepted = true;
        break;
      }
    }
    if (!accepted) return no_fix("Gauss-Newton: no step lowers the cost (stalled before converging)");
  }
  return no_fix("Gauss-Newton did not converge in " + std::to_string(opt.max_iterations) + " iterations");
}

}  // namespace omniloc::landmarks
