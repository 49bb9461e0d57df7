#pragma once
// The field's distance map (paper 002: a pre-computed 2-D look-up table of the distance from a
// world point to the nearest field line), with its gradient. Built once per field and cell size from
// the analytic field model and cached on disk.
#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/field.hpp"

namespace omniloc {

class FieldMap {
 public:
  /// cell: metres (Tribots: 50 mm). `cache_dir`: where to keep the table ("" = no cache).
  FieldMap(const Field& field, double cell = 0.05, const std::string& cache_dir = "");
  /// Distance (metres) to the nearest marking centre line, bilinear between cell centres. Off the
  /// table: the border value plus the distance to the table.
  double distance(const Eigen::Vector2d& p) const;
  /// Distance and its gradient (d/dx, d/dy) of the same bilinear interpolant.
  /// Inline because the matcher and MCL call it ~10^5 times per frame: the call and a std::hypot on
  /// every lookup cost more than the interpolation (issue 20: 17.6 ns per lookup before).
  double distance(const Eigen::Vector2d& p, Eigen::Vector2d* gradient) const {
    const double fx = (p.x() - x0_) / cell_, fy = (p.y() - y0_) / cell_;
    const double cx = std::clamp(fx, 0.0, nx_ - 1.000001), cy = std::clamp(fy, 0.0, ny_ - 1.000001);
    const int i = static_cast<int>(cx), j = static_cast<int>(cy);
    const double ax = cx - i, ay = cy - j;
    const float* row = grid_.data() + static_cast<std::size_t>(j) * nx_ + i;
    const double d00 = row[0], d10 = row[1], d01 = row[nx_], d11 = row[nx_ + 1];
    double d = (1 - ay) * ((1 - ax) * d00 + ax * d10) + ay * ((1 - ax) * d01 + ax * d11);
    if (gradient) {
      gradient->x() = ((1 - ay) * (d10 - d00) + ay * (d11 - d01)) / cell_;
      gradient->y() = ((1 - ax) * (d01 - d00) + ax * (d11 - d10)) / cell_;
    }
    if (fx != cx || fy != cy) off_table(fx - cx, fy - cy, &d, gradient);
    return d;
  }
  double cell() const { return cell_; }
  const std::string& field_fingerprint() const { return fingerprint_; }
  bool loaded_from_cache() const { return from_cache_; }

 private:
  /// Off the table by (dx, dy) cells: adds the distance to the table and points the gradient away.
  void off_table(double dx, double dy, double* d, Eigen::Vector2d* gradient) const;
  double cell_;
  double x0_, y0_;  // world position of cell (0, 0)'s centre
  int nx_, ny_;
  std::vector<float> grid_;
  std::string fingerprint_;
  bool from_cache_ = false;
};

}  // namespace omniloc
