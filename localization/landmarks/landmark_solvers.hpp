#pragma once
// Pose from bearings to known landmarks: closed-form three-landmark solvers from papers 004 and 003,
// a ToTal-like closed form (Pierlot & Van Droogenbroeck 2014), and Gauss-Newton least squares over
// N >= 3 bearings. See docs/landmarks.md.
//
// Input: BearingObs (landmark in the world frame, metres; bearing in the robot frame, radians,
// anticlockwise from the robot's x axis). Output: Fix (pose in the world frame; ok = false with a
// reason, never NaN, on degenerate input or geometry). Position comes from the bearing differences;
// the heading is then the distance-weighted circular mean of atan2(L_i - P) - bearing_i.
//
// Singular sets (no solver can place the robot there, or this solver's formula breaks down):
//  - all: the robot on the circle through the three landmarks (the bearings are the same all along
//    the circle's arc; with N >= 4 landmarks not on one circle least squares has no such set);
//  - three_point_004, two_circle_004: also the robot on the line through a landmark pair whose
//    subtended angle the method divides by (bearing difference 0 or pi);
//  - circle_intersection_003: only the circle (it chooses the pair of circles away from the lines);
//  - total_like: only the circle (an infinite cotangent is replaced by a large finite value).
#include <span>

#include "localization/landmarks/landmark_fix.hpp"

namespace omniloc::landmarks {

/// Paper 004 (Luo, Chiang et al.), three-point method, eqs. (11)-(22): P1, P2, P3 = obs[0..2];
/// phi_0i = obs[i-1].bearing. Angles alpha_102, alpha_203, alpha_321, beta and alpha_210 are
/// normalised to [0, 2 pi) (eq. 20). Singular: robot on the circle through P1, P2, P3, or on the line
/// P1P2 or P2P3 (sin alpha_102 = 0 or sin alpha_203 = 0). Exactly 3 observations.
Fix three_point_004(std::span<const BearingObs> obs);

/// Paper 004, two-circle method, eqs. (1)-(9). Inputs, in the paper's names:
///   obs[0] = D1_L (left edge of the nearer goal D1), obs[1] = D1_R (its right edge, shared by both
///   circles), obs[2] = D2_L (an edge of the farther goal D2);
///   theta1 = bearing(D1_L) - bearing(D1_R): the angle D1_R -> D1_L subtended at the robot R,
///   anticlockwise (circle O1 through R, D1_L, D1_R);
///   theta2 = bearing(D1_R) - bearing(D2_L): the angle D2_L -> D1_R at R (circle O2 through R, D1_R, D2_L).
/// Any three distinct landmarks work; the angles are signed, so the robot may see them in any order.
/// The robot is the second intersection of the two circles (the mirror of D1_R in the line O1O2).
/// Singular: the circle through the three landmarks (O1 = O2), and the lines D1_L D1_R and D1_R D2_L
/// (sin theta1 = 0 or sin theta2 = 0). Exactly 3 observations.
Fix two_circle_004(std::span<const BearingObs> obs);

/// Paper 003 (Zhuang & Cao), circle intersection (sec. 2.1): each pair of landmarks and the robot
/// span a circle; two circles through a shared landmark meet in it and in the robot. The paper gives
/// no equations; centres come from the inscribed-angle theorem, and the shared landmark is the one
/// whose two subtended angles are farthest from 0 and pi (our choice), so the only singular set is
/// the circle through the three landmarks. Exactly 3 observations, any order.
Fix circle_intersection_003(std::span<const BearingObs> obs);

/// Closed-form three-object triangulation of the ToTal kind (Pierlot & Van Droogenbroeck, IEEE T-RO
/// 2014), reimplemented from the published method: cotangents of the bearing differences, modified
/// circle centres relative to the second landmark, one division by the determinant D of the
/// centres' differences (D = 0 on the circle through the landmarks). Any order; works in the whole
/// plane. Exactly 3 observations.
Fix total_like(std::span<const BearingObs> obs);

struct LeastSquaresOptions {
  int max_iterations = 20;
  double step_tol_xy = 1e-9;     ///< metres: converged when a Gauss-Newton step is below both tolerances
  double step_tol_theta = 1e-9;  ///< radians
  /// ... or when the step's predicted cost reduction is below rel_cost_tol * cost (rounding floor).
  double rel_cost_tol = 1e-12;
  int max_halvings = 10;         ///< step halvings when a full step does not lower the cost
};

/// Gauss-Newton on (x, y, theta) minimising sum_i wrap(atan2(L_i - P) - theta - bearing_i)^2 over
/// N >= 3 bearings. Initialised with total_like on the best-spread triple (the triple whose
/// total_like fix has the largest reliability; all triples up to 10 landmarks, else N staggered
/// triples). ok = false if no triple gives a fix, or Gauss-Newton does not converge.
Fix least_squares_bearings(std::span<const BearingObs> obs, const LeastSquaresOptions& opt = {});

}  // namespace omniloc::landmarks
