#include "sim/render/image_blur.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"

namespace omniloc::sim {

namespace {

// OpenCV's pixel-index coordinates (pixel centres at integers, rows as stored, i.e. bottom-up) of a
// render-space point (pixel centres at +0.5, y down).
cv::Point2f to_buffer(int height, const Eigen::Vector2d& p) {
  return {static_cast<float>(p.x() - 0.5), static_cast<float>(height - p.y() - 0.5)};
}

}  // namespace

RotationSmear::RotationSmear(int width, int height, const Eigen::Vector2d& centre, double rim)
    : width_(width), height_(height), rim_(rim), centre_(to_buffer(height, centre)) {
  const double max_r = rim + 2.0;
  nr_ = static_cast<int>(std::ceil(max_r));
  na_ = std::max(64, 4 * static_cast<int>(std::ceil(2.0 * kPi * max_r / 4.0)));  // a sample per pixel at the rim
  // Polar image: row = angle (anticlockwise in the stored buffer), column = radius, both at one
  // pixel's spacing. Tables for cv::remap both ways, computed once.
  cv::Mat px(na_, nr_, CV_32FC1), py(na_, nr_, CV_32FC1);
  for (int a = 0; a < na_; ++a) {
    const double phi = 2.0 * kPi * a / na_, c = std::cos(phi), s = std::sin(phi);
    for (int r = 0; r < nr_; ++r) {
      px.at<float>(a, r) = static_cast<float>(centre_.x + r * c);
      py.at<float>(a, r) = static_cast<float>(centre_.y + r * s);
    }
  }
  cv::convertMaps(px, py, to_polar_a_, to_polar_b_, CV_16SC2);
  cv::Mat bx(height, width, CV_32FC1), by(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double dx = x - centre_.x, dy = y - centre_.y;
      double phi = std::atan2(dy, dx);
      if (phi < 0) phi += 2.0 * kPi;
      bx.at<float>(y, x) = static_cast<float>(std::hypot(dx, dy));
      by.at<float>(y, x) = static_cast<float>(phi * na_ / (2.0 * kPi));
    }
  cv::convertMaps(bx, by, from_polar_a_, from_polar_b_, CV_16SC2);
}

void RotationSmear::apply(const Rgba16View& img, double angle) {
  if (std::fabs(angle) * rim_ < 0.05) return;
  cv::Mat src(img.height, img.width, CV_16UC4, img.data);
  cv::remap(src, polar_, to_polar_a_, to_polar_b_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  // The box average over `d` rows from each row's cell boundary: n whole cells and a fraction of
  // the next, kept as running sums per column and channel. A positive render-space angle is
  // clockwise in the stored (bottom-up) buffer, i.e. towards lower rows.
  const double d = std::fabs(angle) * na_ / (2.0 * kPi);
  const int n = static_cast<int>(std::floor(d));
  const double frac = d - n;
  const int step = angle > 0 ? -1 : 1;
  const int w = nr_ * 4;
  auto row = [&](int i) { return polar_.ptr<std::uint16_t>(((i % na_) + na_) % na_); };
  sum_.assign(static_cast<std::size_t>(w), 0.0);
  for (int k = 0; k < n; ++k) {
    const std::uint16_t* r = row(step * k);
    for (int x = 0; x < w; ++x) sum_[static_cast<std::size_t>(x)] += r[x];
  }
  smeared_.create(na_ + 1, nr_, CV_16UC4);  // + row 0 again: remap reads across the 2 pi seam
  for (int i = 0; i < na_; ++i) {
    const int start = step * i;  // walk the rows in the smear's direction so the running sum stays a window
    const std::uint16_t* tail = row(start + step * n);
    std::uint16_t* o = smeared_.ptr<std::uint16_t>(((start % na_) + na_) % na_);
    for (int x = 0; x < w; ++x) {
      const double v = (sum_[static_cast<std::size_t>(x)] + frac * tail[x]) / d;
      o[x] = static_cast<std::uint16_t>(std::clamp(v + 0.5, 0.0, 65535.0));
    }
    const std::uint16_t* first = row(start);
    for (int x = 0; x < w; ++x) sum_[static_cast<std::size_t>(x)] += static_cast<double>(tail[x]) - first[x];
  }
  smeared_.row(0).copyTo(smeared_.row(na_));
  cv::remap(smeared_, back_, from_polar_a_, from_polar_b_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  // Only inside the rim: outside it the mirror ends and the image stays as drawn.
  const double r2 = rim_ * rim_;
  for (int y = 0; y < img.height; ++y) {
    const double dy = y - centre_.y;
    if (dy * dy > r2) continue;
    const double half = std::sqrt(r2 - dy * dy);
    const int x0 = std::max(0, static_cast<int>(std::ceil(centre_.x - half)));
    const int x1 = std::min(img.width - 1, static_cast<int>(std::floor(centre_.x + half)));
    if (x1 < x0) continue;
    std::copy(back_.ptr<std::uint16_t>(y) + 4 * x0, back_.ptr<std::uint16_t>(y) + 4 * (x1 + 1), src.ptr<std::uint16_t>(y) + 4 * x0);
  }
}

RadialDefocus::RadialDefocus(int width, int height, const Eigen::Vector2d& centre, double rim, const std::vector<double>& sigma_by_radius)
    : width_(width), height_(height) {
  if (!sigma_by_radius.empty()) sigma_max_ = *std::max_element(sigma_by_radius.begin(), sigma_by_radius.end());
  if (!active()) return;
  const cv::Point2f c = to_buffer(height, centre);
  const std::size_t n = sigma_by_radius.size();
  level_.assign(static_cast<std::size_t>(width) * height, 255);
  share_.assign(level_.size(), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double r = std::hypot(x - c.x, y - c.y);
      if (r > rim) continue;
      const double ri = std::min(r, static_cast<double>(n - 1));
      const std::size_t i0 = static_cast<std::size_t>(ri), i1 = std::min(n - 1, i0 + 1);
      const double s = sigma_by_radius[i0] + (ri - static_cast<double>(i0)) * (sigma_by_radius[i1] - sigma_by_radius[i0]);
      const double q = std::clamp(2.0 * s / sigma_max_, 0.0, 2.0);  // in level units
      const int lo = std::min(1, static_cast<int>(q));
      const std::size_t k = static_cast<std::size_t>(y) * width + x;
      level_[k] = static_cast<std::uint8_t>(lo);
      share_[k] = static_cast<std::uint16_t>(std::lround(std::min(65535.0, (q - lo) * 65536.0)));
    }
}

void RadialDefocus::apply(const Rgba16View& img) {
  if (!active()) return;
  cv::Mat src(img.height, img.width, CV_16UC4, img.data);
  cv::GaussianBlur(src, half_, cv::Size(0, 0), 0.5 * sigma_max_, 0.5 * sigma_max_, cv::BORDER_REPLICATE);
  cv::GaussianBlur(src, full_, cv::Size(0, 0), sigma_max_, sigma_max_, cv::BORDER_REPLICATE);
  // Level 0 is the buffer itself: each pixel is read before it is written, the blurred levels were
  // taken before any was.
  const cv::Mat* levels[3] = {&src, &half_, &full_};
  for (int y = 0; y < img.height; ++y) {
    std::uint16_t* o = src.ptr<std::uint16_t>(y);
    const std::uint8_t* lv = &level_[static_cast<std::size_t>(y) * width_];
    const std::uint16_t* sh = &share_[static_cast<std::size_t>(y) * width_];
    for (int x = 0; x < img.width; ++x) {
      if (lv[x] == 255) continue;
      const std::uint16_t* a = levels[lv[x]]->ptr<std::uint16_t>(y) + 4 * x;
      const std::uint16_t* b = levels[lv[x] + 1]->ptr<std::uint16_t>(y) + 4 * x;
      const std::uint32_t wb = sh[x], wa = 65536u - wb;
      for (int ch = 0; ch < 3; ++ch) o[4 * x + ch] = static_cast<std::uint16_t>((wa * a[ch] + wb * b[ch] + 32768u) >> 16);
    }
  }
}

}  // namespace omniloc::sim
