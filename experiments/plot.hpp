#pragma once
// Small plots drawn with OpenCV for experiments' figures (the HTML report redraws the same data
// with matplotlib; these PNGs make every experiment self-contained).
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace omniloc::experiments {

struct Series {
  std::string label;
  std::vector<double> x, y;
};

/// Round tick values covering [lo, hi]: steps of 1, 2 or 5 times a power of ten, at most
/// `max_ticks` + 1 ticks, the first at or below lo and the last at or above hi (e.g. 440..734 ->
/// 400, 500, ..., 800). `integer`: steps of at least 1.
std::vector<double> nice_ticks(double lo, double hi, int max_ticks = 6, bool integer = false);

/// Line plot with axes, ticks and a legend. `log_y`: logarithmic y axis (values must be > 0).
cv::Mat line_plot(const std::vector<Series>& series, const std::string& title, const std::string& xlabel, const std::string& ylabel,
                  bool log_y = false, int width = 720, int height = 440);

/// Heat map of a row-major grid (rows = y from top), with a colour bar and axis ranges.
cv::Mat heat_map(const std::vector<double>& values, int cols, int rows, double x0, double x1, double y0, double y1,
                 const std::string& title, const std::string& xlabel, const std::string& ylabel, int cell_px = 24);

}  // namespace omniloc::experiments
