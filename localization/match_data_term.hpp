#pragma once
// The matcher's data term (paper 002, Lauer et al. 2005): E(q) = sum_i e(d(w_i(q))) with
// e(t) = 1 - c^2 / (c^2 + t^2), where w_i(q) is line point i (robot frame, metres) placed at pose
// q = (x, y, theta) (world frame, metres and radians) and d the field's distance map. RPROP, the
// error reports and the Hessian behind the Kalman covariance evaluate it about twenty times per
// update, so it is the matcher's whole cost (docs/performance.md) and lives apart from the optimiser.
#include <vector>

#include <Eigen/Core>

#include "localization/field_map.hpp"

namespace omniloc {

/// Per-point weights of the data term, E(q) = sum_i w_i e(d(w_i(q))); `total` = sum_i w_i.
struct PointWeights {
  std::vector<double> w;
  double total = 0.0;
};

/// E(q) and, when `grad` is not null, dE / d(x, y, theta) (per metre, per metre, per radian).
/// `weights` (one per point) scale each point's term; null or empty: every point weighs 1 (and the
/// bits are those of an unweighted sum).
/// The same bits on every x86-64 machine: points go two at a time in SSE2 lanes (the loop compiled
/// with AVX2 encodings where the CPU has them), one at a time for a pair with a point off the table
/// and elsewhere; no FMA contraction.
double match_data_term(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c, Eigen::Vector3d* grad,
                       const PointWeights* weights = nullptr);

}  // namespace omniloc
