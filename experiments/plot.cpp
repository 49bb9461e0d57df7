#include "experiments/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace omniloc::experiments {

namespace {
const cv::Scalar kColours[] = {{180, 80, 30}, {40, 120, 230}, {60, 160, 60}, {40, 40, 200}, {150, 90, 160}, {90, 90, 90}, {30, 180, 200}};

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

void text(cv::Mat& m, const std::string& s, cv::Point p, double scale = 0.45, cv::Scalar c = {20, 20, 20}) {
  cv::putText(m, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

// A title at most `max_px` wide: the font shrinks (down to 0.35) rather than the text being clipped
// at the image's edge.
void title_text(cv::Mat& m, const std::string& s, cv::Point p, int max_px) {
  double scale = 0.55;
  int base = 0;
  while (scale > 0.35 && cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base).width > max_px) scale -= 0.025;
  std::string t = s;  // still too long at the smallest size: cut with an ellipsis, never off the edge
  while (t.size() > 4 && cv::getTextSize(t, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &base).width > max_px) t = t.substr(0, t.size() - 4) + "...";
  text(m, t, p, scale);
}
}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int max_ticks, bool integer) {
  if (!(hi > lo)) hi = lo + 1;
  max_ticks = std::max(1, max_ticks);
  const double raw = (hi - lo) / max_ticks;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * mag;
  for (double f : {1.0, 2.0, 5.0})
    if (f * mag >= raw * (1 - 1e-9)) {
      step = f * mag;
      break;
    }
  if (integer) step = std::max(1.0, std::round(step));
  const double first = std::floor(lo / step + 1e-9) * step, last = std::ceil(hi / step - 1e-9) * step;
  std::vector<double> t;
  for (int k = 0; first + k * step <= last + 1e-9 * step; ++k) t.push_back(std::fabs(first + k * step) < 1e-12 * step ? 0.0 : first + k * step);
  return t;
}

cv::Mat line_plot(const std::vector<Series>& series, const std::string& title, const std::string& xlabel, const std::string& ylabel, bool log_y,
                  int width, int height) {
  cv::Mat m(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int l = 70, r = width - 170, t = 60, b = height - 50;
  double xmin = std::numeric_limits<double>::max(), xmax = -xmin, ymin = xmin, ymax = -xmin;
  auto ty = [&](double y) { return log_y ? std::log10(std::max(y, 1e-12)) : y; };
  for (const auto& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, ty(s.y[i]));
      ymax = std::max(ymax, ty(s.y[i]));
    }
  if (xmin > xmax) xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  // Integer data (robot counts, iterations) get integer ticks; every axis gets round ones.
  bool integer_x = true;
  for (const auto& s : series)
    for (double x : s.x) integer_x = integer_x && std::fabs(x - std::round(x)) < 1e-9;
  if (xmax - xmin < 1e-12) xmax = xmin + 1;
  if (ymax - ymin < 1e-12) ymax = ymin + 1;
  const std::vector<double> xt = nice_ticks(xmin, xmax, 6, integer_x);
  xmin = xt.front();
  xmax = xt.back();
  // Quantities that cannot be negative (errors, entropy, counts) start at zero, never below it; a
  // log axis gets its ticks at whole decades.
  std::vector<double> yt;
  if (log_y) {
    for (double d = std::floor(ymin); d <= std::ceil(ymax) + 1e-9; d += 1.0) yt.push_back(d);
    if (yt.size() < 2) yt.push_back(yt.front() + 1);
  } else {
    yt = nice_ticks(ymin >= 0.0 ? 0.0 : ymin, ymax, 5);
  }
  ymin = yt.front();
  ymax = yt.back();
  auto P = [&](double x, double y) {
    return cv::Point(static_cast<int>(l + (x - xmin) / (xmax - xmin) * (r - l)), static_cast<int>(b - (ty(y) - ymin) / (ymax - ymin) * (b - t)));
  };
  cv::rectangle(m, {l, t}, {r, b}, {0, 0, 0}, 1);
  for (double xv : xt) {
    const int xp = static_cast<int>(l + (xv - xmin) / (xmax - xmin) * (r - l));
    cv::line(m, {xp, b}, {xp, b + 4}, {0, 0, 0});
    text(m, num(xv), {xp - 12, b + 18});
  }
  for (double yv : yt) {
    const int yp = static_cast<int>(b - (yv - ymin) / (ymax - ymin) * (b - t));
    cv::line(m, {l - 4, yp}, {l, yp}, {0, 0, 0});
    cv::line(m, {l, yp}, {r, yp}, {230, 230, 230});
    text(m, num(log_y ? std::pow(10.0, yv) : yv), {4, yp + 4});
  }
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    const cv::Scalar c = kColours[k % 7];
    for (std::size_t i = 1; i < s.x.size() && i < s.y.size(); ++i) cv::line(m, P(s.x[i - 1], s.y[i - 1]), P(s.x[i], s.y[i]), c, 2, cv::LINE_AA);
    if (s.x.size() == 1) cv::circle(m, P(s.x[0], s.y[0]), 3, c, -1);
    const int ly = t + 10 + 20 * static_cast<int>(k);
    cv::line(m, {r + 10, ly}, {r + 30, ly}, c, 2);
    text(m, s.label, {r + 36, ly + 5}, 0.42);
  }
  title_text(m, title, {8, 24}, width - 16);
  text(m, xlabel, {(l + r) / 2 - 40, height - 12});
  text(m, ylabel + (log_y ? " (log)" : ""), {4, t - 16}, 0.42);
  return m;
}

cv::Mat heat_map(const std::vector<double>& v, int cols, int rows, double x0, double x1, double y0, double y1, const std::string& title,
                 const std::string& xlabel, const std::string& ylabel, int cell) {
  const int l = 70, t = 36, w = cols * cell, h = rows * cell;
  cv::Mat m(h + t + 50, w + l + 110, CV_8UC3, cv::Scalar(255, 255, 255));
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (double x : v)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  if (lo > hi) lo = 0, hi = 1;
  if (hi - lo < 1e-12) hi = lo + 1;
  cv::Mat grey(1, 256, CV_8UC1), lut;
  for (int i = 0; i < 256; ++i) grey.at<uchar>(0, i) = static_cast<uchar>(i);
  cv::applyColorMap(grey, lut, cv::COLORMAP_VIRIDIS);
  auto colour = [&](double x) {
    const int i = std::clamp(static_cast<int>((x - lo) / (hi - lo) * 255.0), 0, 255);
    const cv::Vec3b c = lut.at<cv::Vec3b>(0, i);
    return cv::Scalar(c[0], c[1], c[2]);
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const double x = v[static_cast<std::size_t>(r) * cols + c];
      cv::rectangle(m, {l + c * cell, t + r * cell}, {l + (c + 1) * cell - 1, t + (r + 1) * cell - 1}, std::isfinite(x) ? colour(x) : cv::Scalar(200, 200, 200), -1);
    }
  cv::rectangle(m, {l, t}, {l + w, t + h}, {0, 0, 0});
  text(m, num(x0), {l, t + h + 18});
  text(m, num(x1), {l + w - 20, t + h + 18});
  text(m, num(y0), {4, t + 12});
  text(m, num(y1), {4, t + h});
  for (int k = 0; k < h; ++k) cv::line(m, {l + w + 20, t + k}, {l + w + 40, t + k}, colour(hi - (hi - lo) * k / std::max(1, h - 1)));
  text(m, num(hi), {l + w + 44, t + 10});
  text(m, num(lo), {l + w + 44, t + h});
  title_text(m, title, {8, 22}, m.cols - 16);
  text(m, xlabel, {l + w / 2 - 30, t + h + 38});
  text(m, ylabel, {4, t - 8}, 0.42);
  return m;
}

}  // namespace omniloc::experiments
