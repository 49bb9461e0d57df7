#pragma once
// Association of line points with the field's markings (core/field: the exact centre lines of
// segments and arcs), as B-Human's SelfLocator associates line percepts with field lines before its
// UKF update: a world point is assigned the nearest marking, and the measurement is its signed
// distance to that marking, h = 0 on the line. For a segment it is the distance to the segment's
// line (linear in the point), for an arc the distance to its circle, for a point beyond a marking's
// ends the distance to that end. The nearest marking comes from a grid built once: each cell keeps
// the three markings nearest its centre, and the exact distances to those decide (the nearest
// marking of any point of a cell is among them unless three markings meet within a cell's
// half-diagonal, which the field's line spacing rules out at the default 0.1 m cell).
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"

namespace omniloc::modern {

/// One marking's local measurement model, fixed at association time (at the hypothesis mean):
/// value(w) = n . w - offset (a line), or sign (|w - centre| - radius) (a circle). The sign makes the
/// value at the associating point equal to its distance (>= 0).
struct LocalMarking {
  bool circle = false;
  Eigen::Vector2d n{0.0, 0.0};       ///< unit normal (line)
  double offset = 0.0;               ///< line: n . (a point of the line)
  Eigen::Vector2d centre{0.0, 0.0};  ///< circle
  double radius = 0.0, sign = 1.0;   ///< circle
  int marking = -1;                  ///< index in MarkingAssociation's list
  double distance = 0.0;             ///< |value| at the associating point, metres
  double value(double x, double y) const {
    if (circle) return sign * (std::hypot(x - centre.x(), y - centre.y()) - radius);
    return n.x() * x + n.y() * y - offset;
  }
  /// d(value)/d(w): the unit normal of the marking at w (pointing to growing values).
  Eigen::Vector2d gradient(const Eigen::Vector2d& w) const {
    if (!circle) return n;
    const Eigen::Vector2d d = w - centre;
    const double r = d.norm();
    return r > 1e-9 ? Eigen::Vector2d(sign * d / r) : Eigen::Vector2d(0.0, 0.0);
  }
};

class MarkingAssociation {
 public:
  /// `cell`: metres; the grid reaches `reach` metres beyond the floor (points off the floor are
  /// outliers anyway, and get the exact search).
  explicit MarkingAssociation(const Field& field, double cell = 0.1, double reach = 1.0);
  /// The nearest marking of world point w and its local model there.
  LocalMarking associate(const Eigen::Vector2d& w) const;
  /// Exact distance of w to marking k (segments first, then arcs, in the field's order).
  double distance(int k, const Eigen::Vector2d& w) const;
  int markings() const { return static_cast<int>(segments_.size() + arcs_.size()); }

 private:
  LocalMarking local(int k, const Eigen::Vector2d& w) const;
  std::vector<SegmentMarking> segments_;
  std::vector<ArcMarking> arcs_;
  double x0_ = 0, y0_ = 0, inv_cell_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<std::array<std::int16_t, 3>> nearest_;  // per cell, -1 where fewer markings
};

}  // namespace omniloc::modern
