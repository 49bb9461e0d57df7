#pragma once
// The field's distance map (paper 002: a pre-computed 2-D look-up table of the distance from a
// world point to the nearest field line), with its gradient. Built once per field and cell size from
// the analytic field model and cached on disk.
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
  double distance(const Eigen::Vector2d& p, Eigen::Vector2d* gradient) const;
  double cell() const { return cell_; }
  const std::string& field_fingerprint() const { return fingerprint_; }
  bool loaded_from_cache() const { return from_cache_; }

 private:
  double at(int i, int j) const { return grid_[static_cast<std::size_t>(j) * nx_ + i]; }
  double cell_;
  double x0_, y0_;  // world position of cell (0, 0)'s centre
  int nx_, ny_;
  std::vector<float> grid_;
  std::string fingerprint_;
  bool from_cache_ = false;
};

}  // namespace omniloc
