#include "localization/landmarks/landmark_solvers.hpp"

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "core/angles.hpp"
#include "core/fast_trig.hpp"
#include "localization/landmarks/triple_fix.hpp"

namespace omniloc::landmarks {
namespace {

using detail::finish_triple;
using detail::triple_ok;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// (cos, sin) of the bearings relative to the first, bearing_i - bearing_0 (so c[0] = 1, s[0] = 0):
/// the position depends on bearing differences only, and the heading is that of the rotated
/// bearings minus bearing_0 (finish_triple), so two sincos are enough. sincos_fast: inline, within
/// ~2 ulp of libm (the libm calls were a quarter of a solve). The differences are rounded to the
/// ulp of the bearings, i.e. 4e-16 rad for bearings in (-pi, pi] (7e-12 rad at 1e5).
inline void relative_cs(std::span<const BearingObs> obs, double c[3], double s[3]) {
  c[0] = 1.0;
  s[0] = 0.0;
  sincos_fast(obs[1].bearing - obs[0].bearing, s[1], c[1]);
  sincos_fast(obs[2].bearing - obs[0].bearing, s[2], c[2]);
}

std::string line_reason(int i, int j) {
  return "robot on the line through landmarks " + std::to_string(i) + " and " + std::to_string(j) +
         " (bearing difference 0 or pi)";
}

const char* const kOnCircle = "robot on the circle through the three landmarks";

/// The refusal for input that detail::triple_ok rejected (check_triple says why).
Fix bad_input(std::span<const BearingObs> obs) {
  std::string r = check_triple(obs);
  return no_fix(r.empty() ? std::string("invalid input") : std::move(r));
}

}  // namespace

// Angles below are handled as (cos, sin) pairs: a difference of bearings b_j - b_i is
// (c_i c_j + s_i s_j, c_i s_j - s_i c_j), a sum of angles a complex product, a rotation by an angle
// a 2 x 2 product. That is the papers' equations with the angle-sum identities applied, so each
// solver needs the three bearings' sincos, one atan2 (the heading) and no other transcendental
// call; wrapping angles to [0, 2 pi) or (-pi, pi] does not change a (cos, sin) pair, so the
// normalisations the papers ask for (eq. 20 of paper 004) hold by construction.

// ---------------------------------------------------------------------------------------------
Fix three_point_004(std::span<const BearingObs> obs) {
  double far2 = 0.0;
  if (!triple_ok(obs, far2)) return bad_input(obs);
  double c[3], s[3];
  relative_cs(obs, c, s);
  const Eigen::Vector2d& P1 = obs[0].landmark;
  const Eigen::Vector2d& P2 = obs[1].landmark;
  const Eigen::Vector2d& P3 = obs[2].landmark;

  // Eqs. (11)-(14): distances and directions from P2 to P1 and P3 (the directions phi21, phi23 as
  // the offsets themselves: tan^-1 taken with its quadrant).
  const Eigen::Vector2d v21 = P1 - P2, v23 = P3 - P2;
  const double d21 = v21.norm();
  const double d23 = v23.norm();
  // Eqs. (15)-(18) as (cos, sin): alpha102 = phi02 - phi01, alpha203 = phi03 - phi02,
  // alpha321 = phi21 - phi23, beta = 2 pi - alpha102 - alpha203 - alpha321.
  const double c102 = c[0] * c[1] + s[0] * s[1], s102 = c[0] * s[1] - s[0] * c[1];
  const double s203 = c[1] * s[2] - s[1] * c[2];
  if (std::fabs(s102) < kSingularTol) return no_fix(line_reason(0, 1));
  if (std::fabs(s203) < kSingularTol) return no_fix(line_reason(1, 2));
  // alpha102 + alpha203 = phi03 - phi01; alpha321 from the unit offsets.
  const double c13 = c[0] * c[2] + s[0] * s[2], s13 = c[0] * s[2] - s[0] * c[2];
  const double inv_dd = 1.0 / (d21 * d23);
  const double c321 = (v23.x() * v21.x() + v23.y() * v21.y()) * inv_dd;
  const double s321 = (v23.x() * v21.y() - v23.y() * v21.x()) * inv_dd;
  const double cos_beta = c13 * c321 - s13 * s321;     // cos(-sigma) = cos(sigma)
  const double sin_beta = -(s13 * c321 + c13 * s321);  // sin(-sigma), sigma = a102 + a203 + a321
  // Eq. (19). It comes from the law of sines in triangles P0P1P2 and P0P2P3 (both giving |P0P2|):
  // tan(alpha210) = sin(beta) / (k + cos(beta)), k = d21 sin(alpha203) / (d23 sin(alpha102)).
  // A one-argument tan^-1 fixes alpha210 only modulo pi and the paper's normalisation to [0, 2 pi)
  // does not choose the branch; we take the branch with |P0P2| = d21 sin(alpha210) / sin(alpha102) > 0,
  // i.e. sin(alpha210) of the sign of sin(alpha102) (paper silent; our choice).
  const double k = d21 * s203 / (d23 * s102);
  const double num = sin_beta, den = k + cos_beta;
  // On the circle through P1, P2, P3 the quadrilateral P0P1P2P3 is cyclic: num = den = 0.
  const double h2 = num * num + den * den;
  const double tol = kSingularTol * std::max(1.0, std::fabs(k));
  if (h2 < tol * tol) return no_fix(kOnCircle);
  // alpha210 = atan2(sg num, sg den) as (cos, sin): the normalised pair.
  const double sg_h = (s102 > 0.0 ? 1.0 : -1.0) / std::sqrt(h2);
  const double c210 = sg_h * den, s210 = sg_h * num;
  // Eq. (21): P0 = P1 + |P1P0| (cos, sin)(pi + phi21 + alpha210), |P1P0| = d21 sin(pi - alpha102 -
  // alpha210) / sin(alpha102) by the law of sines; sin(pi - a) = sin(a), and d21 times the unit
  // vector of phi21 rotated by alpha210 is v21 rotated by alpha210; the + pi negates it.
  const double s_sum = s102 * c210 + c102 * s210;  // sin(alpha102 + alpha210)
  const double f = -s_sum / s102;
  const Eigen::Vector2d P0(P1.x() + f * (c210 * v21.x() - s210 * v21.y()), P1.y() + f * (s210 * v21.x() + c210 * v21.y()));
  // Eq. (22) gives the heading from P1 alone: phi0 = phi21 + alpha210 - phi01 (the direction P0 -> P1
  // minus its bearing). finish_triple computes the same quantity averaged over the three landmarks.
  return finish_triple(obs, c, s, obs[0].bearing, P0, far2);
}

// ---------------------------------------------------------------------------------------------
Fix two_circle_004(std::span<const BearingObs> obs) {
  double far2 = 0.0;
  if (!triple_ok(obs, far2)) return bad_input(obs);
  double c[3], s[3];
  relative_cs(obs, c, s);
  const Eigen::Vector2d& D1L = obs[0].landmark;
  const Eigen::Vector2d& D1R = obs[1].landmark;
  const Eigen::Vector2d& D2L = obs[2].landmark;
  // Subtended angles at R, signed anticlockwise (the paper's theta1, theta2; it has D1_L to the
  // left of D1_R, so theta1 > 0 there), as (cos, sin): theta1 = bearing0 - bearing1,
  // theta2 = bearing1 - bearing2.
  const double c1 = c[1] * c[0] + s[1] * s[0], s1 = c[1] * s[0] - s[1] * c[0];
  const double c2 = c[2] * c[1] + s[2] * s[1], s2 = c[2] * s[1] - s[2] * c[1];
  if (std::fabs(s1) < kSingularTol) return no_fix(line_reason(0, 1));
  if (std::fabs(s2) < kSingularTol) return no_fix(line_reason(1, 2));
  // Eqs. (1)-(4): O = D + R(90deg - theta) (V / 2) / cos(90deg - theta); R(.) the rotation matrix.
  // The triangle D, O, chord midpoint has its angle 90deg - theta at D (central angle 2 theta).
  // cos(90deg - theta) = sin theta, sin(90deg - theta) = cos theta.
  const auto centre = [](const Eigen::Vector2d& V, const Eigen::Vector2d& D, double ct, double st) {
    const double q = 0.5 / st;
    return Eigen::Vector2d(D.x() + q * (st * V.x() - ct * V.y()), D.y() + q * (ct * V.x() + st * V.y()));
  };
  const Eigen::Vector2d V_D1 = D1L - D1R;              // (1)
  const Eigen::Vector2d O1 = centre(V_D1, D1R, c1, s1);  // (2)
  const Eigen::Vector2d V_D2 = D1R - D2L;              // (3)
  const Eigen::Vector2d O2 = centre(V_D2, D2L, c2, s2);  // (4)
  const Eigen::Vector2d V_OD2 = D1R - O2;              // (5)
  const Eigen::Vector2d V_O = O1 - O2;                 // (6)
  // Both circles pass through D1_R; they coincide when R is on the circle through all three.
  const double radius2 = std::max(V_OD2.squaredNorm(), (D1R - O1).squaredNorm());
  const double vo2 = V_O.squaredNorm();
  if (!(vo2 >= kSingularTol * kSingularTol * radius2)) return no_fix(kOnCircle);
  // Eq. (7): theta_OD = angle between V_OD2 and V_O, whose (cos, sin) are (dot, |cross|) over the
  // product of the norms (acos of the normalised dot product would lose half the digits near 0 and pi).
  const double cr = cross(V_O, V_OD2);
  const double dt = V_O.dot(V_OD2);
  // Eqs. (8)-(9): R = R(+-2 theta_OD) V_OD2 + O2, the mirror image of D1_R in the line O2O1. The
  // paper writes +2 theta_OD in (8) and -2 theta_OD in (9); the right sign depends on the side of
  // O2O1 that D1_R lies on: rotate V_OD2 back across V_O (clockwise when V_OD2 is anticlockwise of
  // V_O, i.e. by -2 theta_OD when cr > 0). Double-angle formulas: cos(2 t) = (dt^2 - cr^2) / n,
  // sin(2 t) = 2 |cr| dt / n, n = dt^2 + cr^2; with the sign rule, sin(rot) = -2 cr dt / n.
  const double inv_n = 1.0 / (dt * dt + cr * cr);
  const double cr2 = (dt * dt - cr * cr) * inv_n, sr2 = -2.0 * cr * dt * inv_n;
  const Eigen::Vector2d R(cr2 * V_OD2.x() - sr2 * V_OD2.y() + O2.x(), sr2 * V_OD2.x() + cr2 * V_OD2.y() + O2.y());
  return finish_triple(obs, c, s, obs[0].bearing, R, far2);
}

// ---------------------------------------------------------------------------------------------
Fix circle_intersection_003(std::span<const BearingObs> obs) {
  double far2 = 0.0;
  if (!triple_ok(obs, far2)) return bad_input(obs);
  double c[3], s[3];
  relative_cs(obs, c, s);
  // sin of the angle subtended at the robot by each pair (bearing_j - bearing_i for (i, j) = (0, 1),
  // (1, 2), (2, 0)).
  const double s01 = c[0] * s[1] - s[0] * c[1];
  const double s12 = c[1] * s[2] - s[1] * c[2];
  const double s20 = c[2] * s[0] - s[2] * c[0];
  // Shared landmark k: the two circles are (L_k, L_i, R) and (L_k, L_j, R), i = k + 1, j = k + 2
  // (mod 3). Choose k so that both subtended angles are farthest from 0 and pi (a circle's centre
  // goes to infinity as its angle does); then only the circle through all three landmarks is
  // singular. Paper silent; our choice. The first best k in the order 0, 1, 2.
  const double q0 = std::min(std::fabs(s01), std::fabs(s20));
  const double q1 = std::min(std::fabs(s12), std::fabs(s01));
  const double q2 = std::min(std::fabs(s20), std::fabs(s12));
  const std::size_t k = q0 >= q1 ? (q0 >= q2 ? 0 : 2) : (q1 >= q2 ? 1 : 2);
  const double best = std::max(q0, std::max(q1, q2));
  if (best < kSingularTol) return no_fix("robot on the lines through two landmark pairs");
  const std::size_t i = k == 2 ? 0 : k + 1, j = k == 0 ? 2 : k - 1;
  const Eigen::Vector2d& Lk = obs[k].landmark;
  // Centre of the circle through A = L_k, B and the robot R that sees the chord A -> B under the
  // signed angle theta = bearing(B) - bearing(A) (cos ct, sin st != 0). Inscribed-angle theorem: the
  // centre is on the chord's perpendicular bisector, cot(theta) / 2 chord lengths to the left of A -> B:
  // O = (A + B) / 2 + cot(theta) / 2 * perp(B - A).
  const auto centre = [&](std::size_t b) {
    const Eigen::Vector2d& B = obs[b].landmark;
    const double ct = c[k] * c[b] + s[k] * s[b], st = c[k] * s[b] - s[k] * c[b];
    const double h = 0.5 * ct / st;
    return Eigen::Vector2d(0.5 * (Lk.x() + B.x()) - h * (B.y() - Lk.y()), 0.5 * (Lk.y() + B.y()) + h * (B.x() - Lk.x()));
  };
  const Eigen::Vector2d Oa = centre(i);
  const Eigen::Vector2d Ob = centre(j);
  // The common chord L_k R is perpendicular to the line of centres: R is the mirror of L_k in it.
  const Eigen::Vector2d u = Ob - Oa;
  const Eigen::Vector2d a = Lk - Oa;
  const double radius2 = std::max(a.squaredNorm(), (Lk - Ob).squaredNorm());
  const double u2 = u.squaredNorm();
  if (!(u2 >= kSingularTol * kSingularTol * radius2)) return no_fix(kOnCircle);
  const double t = a.dot(u) / u2;
  const Eigen::Vector2d R(2.0 * (Oa.x() + t * u.x()) - Lk.x(), 2.0 * (Oa.y() + t * u.y()) - Lk.y());
  return finish_triple(obs, c, s, obs[0].bearing, R, far2);
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
inline double cot_safe(double c, double s) {
  if (std::fabs(s) * kCotMax > std::fabs(c)) return c / s;
  return std::signbit(s) != std::signbit(c) ? -kCotMax : kCotMax;
}
}  // namespace

Fix total_like(std::span<const BearingObs> obs) {
  double far2 = 0.0;
  if (!triple_ok(obs, far2)) return bad_input(obs);
  double c[3], s[3];
  relative_cs(obs, c, s);
  // ToTal (Pierlot, Van Droogenbroeck, "A New Three Object Triangulation Algorithm for Mobile Robot
  // Positioning", IEEE T-RO 30(3), 2014), formulated here from its equations; our own code.
  // x12..y31 are twice the centres of the circles (B1, B2, R), (B2, B3, R), (B3, B1, R) relative
  // to B2, k31 is the power-like term of the third circle, and
  //   D = (x12 - x23)(y23 - y31) - (y12 - y23)(x23 - x31),  R = B2 + k31 (y12 - y23, x23 - x12) / D.
  // D and the numerator are linear in T31 = cot(alpha31), but c12 and c23 enter D twice (both
  // factors): a clamped, huge T12 or T23 makes D the difference of two products of size T^2 whose
  // difference is of size T, and the cancellation cost up to 4 mm on the line through the second
  // and third landmarks before commit 16640f5. As in ToTal, only T31 may be infinite: the landmarks are
  // renumbered cyclically (which keeps every signed angle) so that the pair whose bearing
  // difference is nearest 0 or pi is (3, 1). The robot is on at most one of the three lines
  // (two meet only at a landmark, refused by check_triple), so T12 and T23 stay finite and of
  // moderate size, and the clamped T31 = +-kCotMax moves R by ~1e-11 m at most (see cot_safe).
  //
  // (cos, sin) of the bearing differences b1 - b0, b2 - b1, b0 - b2 (original numbering).
  const double e01c = c[0] * c[1] + s[0] * s[1], e01s = c[0] * s[1] - s[0] * c[1];
  const double e12c = c[1] * c[2] + s[1] * s[2], e12s = c[1] * s[2] - s[1] * c[2];
  const double e20c = c[2] * c[0] + s[2] * s[0], e20s = c[2] * s[0] - s[2] * c[0];
  // Rotation r: B1, B2, B3 = obs[r], obs[r + 1], obs[r + 2] (mod 3); pair (r + 2, r) is the one
  // whose |sin| is smallest (ties as before: pair (0, 1) only when strictly smallest, then (1, 2)).
  const double a01 = std::fabs(e01s), a12 = std::fabs(e12s), a20 = std::fabs(e20s);
  const bool r1 = a01 < a12 && a01 < a20;          // pair (0, 1) becomes (3, 1)
  const bool r2 = !r1 && a12 < a20 && a12 <= a01;  // pair (1, 2) becomes (3, 1)
  // Branch-free selection (which pair is nearest 0 or pi is data, not predictable).
  const double cA = r1 ? e12c : (r2 ? e20c : e01c), sA = r1 ? e12s : (r2 ? e20s : e01s);  // pair 1-2
  const double cB = r1 ? e20c : (r2 ? e01c : e12c), sB = r1 ? e20s : (r2 ? e01s : e12s);  // pair 2-3
  const double cC = r1 ? e01c : (r2 ? e12c : e20c), sC = r1 ? e01s : (r2 ? e12s : e20s);  // pair 3-1
  const std::size_t rot = static_cast<std::size_t>(r1) + 2 * static_cast<std::size_t>(r2);
  static constexpr std::size_t kNext[5] = {0, 1, 2, 0, 1};
  const Eigen::Vector2d& B1 = obs[rot].landmark;
  const Eigen::Vector2d& B2 = obs[kNext[rot + 1]].landmark;
  const Eigen::Vector2d& B3 = obs[kNext[rot + 2]].landmark;
  // Landmarks relative to the second one.
  const Eigen::Vector2d p1 = B1 - B2;
  const Eigen::Vector2d p3 = B3 - B2;
  // Cotangents of the bearing differences (angles subtended at the robot by the pairs 1-2, 2-3, 3-1).
  const double T12 = cot_safe(cA, sA);
  const double T23 = cot_safe(cB, sB);
  const double T31 = cot_safe(cC, sC);  // the only one that can be clamped
  // Modified centres: twice the centres of the circles (B1, B2, R), (B2, B3, R), (B3, B1, R),
  // relative to B2 (inscribed-angle theorem, as in circle_intersection_003).
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
  // dnorm = n12 n23 + n23 n31 + n31 n12 (n the centres' norms) is at most n12^2 + n23^2 + n31^2
  // (ab <= (a^2 + b^2) / 2), so the square roots are needed only when |D| is below that bound times
  // 1e-14, i.e. near the circle: the same decision, without three square roots on the common path.
  const double q12 = c12.squaredNorm(), q23 = c23.squaredNorm(), q31 = c31.squaredNorm();
  if (!(std::fabs(D) > 1e-14 * (q12 + q23 + q31))) {
    const double n12 = std::sqrt(q12), n23 = std::sqrt(q23), n31 = std::sqrt(q31);
    const double dnorm = n12 * n23 + n23 * n31 + n31 * n12;
    if (!(std::fabs(D) > 1e-14 * dnorm)) return no_fix(kOnCircle);
  }
  const double invD = 1.0 / D;  // the single division
  const Eigen::Vector2d R(B2.x() + k31 * (c12.y() - c23.y()) * invD, B2.y() + k31 * (c23.x() - c12.x()) * invD);
  return finish_triple(obs, c, s, obs[0].bearing, R, far2);
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
