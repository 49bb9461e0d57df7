#pragma once
// The field's distance map (paper 002: a pre-computed 2-D look-up table of the distance from a
// world point to the nearest field line), with its gradient. Built once per field and cell size from
// the analytic field model and cached on disk.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/field.hpp"

namespace omniloc {

class FieldMap {
 public:
  /// A lookup's result: distance (metres) and, when asked for, its gradient (d/dx, d/dy).
  struct Sample {
    double d, gx, gy;
  };
  /// The table as plain values: what a hot loop copies into a local (`const auto t = map.table()`)
  /// so the compiler keeps the geometry in registers instead of reloading it around every lookup
  /// (before commit 8c2a23f the matcher's loop reloaded seven members per point). Results are returned by
  /// value for the same reason: an out-pointer into the loop would pin its variables to memory.
  struct Table {
    const double* cells;     // row-major, nx per row (metres)
    std::ptrdiff_t nx;
    double x0, y0;           // world position (metres) of cell (0, 0)'s centre
    double inv_cell, cell;   // 1 / metres, metres
    double last_x, last_y;   // nx - 1, ny - 1: the fast path's bounds (cells)
    unsigned last_i, last_j; // the same as cell indices
    /// World x, y (metres) -> table position (cells), as at() and the hot loops take it.
    double cells_x(double x) const { return (x - x0) * inv_cell; }
    double cells_y(double y) const { return (y - y0) * inv_cell; }
    /// At world point (x, y) (metres); the gradient (per metre) only with kGradient, else 0.
    template <bool kGradient>
    Sample at(double x, double y) const {
      Sample s = at_cells<kGradient>(cells_x(x), cells_y(y));
      if constexpr (kGradient) {
        s.gx *= inv_cell;
        s.gy *= inv_cell;
      }
      return s;
    }
    /// At table position (fx, fy) = ((x - x0) / cell, (y - y0) / cell); the gradient per cell
    /// (metres of distance per cell of motion). Hot loops work in these units: the rotation and
    /// the scaling fold into one multiplication per coordinate. One range test instead of two
    /// clamps; off the table (or on its last row / column) the out-of-line path.
    template <bool kGradient>
    Sample at_cells(double fx, double fy) const {
      // On the table iff 0 <= fx < nx - 1 and 0 <= fy < ny - 1: the cell indices (truncated) as
      // unsigned below nx - 1, ny - 1 (a negative index, or NaN's and a huge value's INT_MIN, wraps
      // above), and the smaller coordinate not negative (fx in (-1, 0) truncates to 0).
      const int i = truncate(fx), j = truncate(fy);
      if (!(static_cast<unsigned>(i) < last_i && static_cast<unsigned>(j) < last_j && std::min(fx, fy) >= 0.0)) [[unlikely]]
        return off_table(*this, fx, fy, kGradient);
      return interpolate<kGradient>(fx, fy, i, j);
    }
    /// Truncation to int defined for every double: INT_MIN for NaN and for values beyond int's
    /// range (a plain cast is undefined behaviour there, which UBSan reports; SSE2's cvttsd2si, the
    /// instruction the cast compiles to, gives exactly this, so the hot loops pay nothing).
    static int truncate(double v) {
#if defined(__SSE2__)
      return _mm_cvttsd_si32(_mm_set_sd(v));
#else
      return v > -2147483649.0 && v < 2147483648.0 ? static_cast<int>(v) : std::numeric_limits<int>::min();
#endif
    }
    /// The bilinear interpolant at a table position inside [0, nx - 1) x [0, ny - 1).
    template <bool kGradient>
    Sample interpolate(double cx, double cy) const {
      return interpolate<kGradient>(cx, cy, static_cast<int>(cx), static_cast<int>(cy));
    }
    /// The same with the cell (i, j) = (floor(cx), floor(cy)) known.
    template <bool kGradient>
    Sample interpolate(double cx, double cy, int i, int j) const {
      const double ax = cx - i, ay = cy - j;
      const double* row = cells + j * nx + i;
      const double d00 = row[0], d10 = row[1], d01 = row[nx], d11 = row[nx + 1];
      // Horner form: along x on both rows, then between the rows.
      const double dx0 = d10 - d00, dx1 = d11 - d01;
      const double lo = d00 + ax * dx0, hi = d01 + ax * dx1;
      if constexpr (kGradient) return {lo + ay * (hi - lo), dx0 + ay * (dx1 - dx0), hi - lo};
      return {lo + ay * (hi - lo), 0.0, 0.0};
    }
    /// Off the table by table position (fx, fy): the interpolant at the nearest table point plus
    /// the distance to the table, the gradient (per cell) pointing away from it. The table by
    /// value, so a caller's local copy never escapes.
    static Sample off_table(Table t, double fx, double fy, bool gradient);
  };

  /// cell: metres (Tribots: 50 mm). `cache_dir`: where to keep the table ("" = no cache).
  FieldMap(const Field& field, double cell = 0.05, const std::string& cache_dir = "");
  // table_ points into grid_: a copy re-points it, a move keeps the buffer and so the pointer.
  FieldMap(const FieldMap& o) : grid_(o.grid_), table_(o.table_), fingerprint_(o.fingerprint_), from_cache_(o.from_cache_) {
    table_.cells = grid_.data();
  }
  FieldMap& operator=(const FieldMap& o) {
    if (this != &o) *this = FieldMap(o);
    return *this;
  }
  FieldMap(FieldMap&&) noexcept = default;
  FieldMap& operator=(FieldMap&&) noexcept = default;
  /// Distance (metres) to the nearest marking centre line, bilinear between cell centres. Off the
  /// table: the border value plus the distance to the table.
  double distance(const Eigen::Vector2d& p) const { return table_.at<false>(p.x(), p.y()).d; }
  /// Distance and its gradient (d/dx, d/dy) of the same bilinear interpolant.
  double distance(const Eigen::Vector2d& p, Eigen::Vector2d* gradient) const {
    if (!gradient) return distance(p);
    const Sample s = table_.at<true>(p.x(), p.y());
    *gradient = Eigen::Vector2d(s.gx, s.gy);
    return s.d;
  }
  const Table& table() const { return table_; }
  double cell() const { return table_.cell; }
  const std::string& field_fingerprint() const { return fingerprint_; }
  bool loaded_from_cache() const { return from_cache_; }

 private:
  std::vector<double> grid_;  // the cached floats, widened: no conversion in the lookups
  Table table_{};
  std::string fingerprint_;
  bool from_cache_ = false;
};

}  // namespace omniloc
