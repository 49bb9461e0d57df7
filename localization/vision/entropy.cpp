#include "localization/vision/entropy.hpp"

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace omniloc {

namespace {
cv::Mat wrap(const Image& img) {
  return cv::Mat(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.rgb.data()));
}
cv::Mat disc_mask(const Image& img, const Eigen::Vector2d& c, double r) {
  cv::Mat mask(img.height, img.width, CV_8UC1, cv::Scalar(0));
  cv::circle(mask, cv::Point(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y()))), static_cast<int>(std::lround(r)),
             cv::Scalar(255), -1);
  return mask;
}
}  // namespace

double image_entropy(const Image& img, const Eigen::Vector2d& centre, double outer_radius_px) {
  if (img.empty()) return 0.0;
  const cv::Mat m = wrap(img);
  const cv::Mat mask = outer_radius_px > 0 ? disc_mask(img, centre, outer_radius_px) : cv::Mat();
  double h = 0.0;
  const int hist_size = 256;
  const float range[] = {0.f, 256.f};
  const float* ranges = range;
  for (int ch = 0; ch < 3; ++ch) {
    cv::Mat hist;
    cv::calcHist(&m, 1, &ch, mask, hist, 1, &hist_size, &ranges);
    const double n = cv::sum(hist)[0];
    if (n <= 0) continue;
    for (int k = 0; k < hist_size; ++k) {
      const double p = hist.at<float>(k) / n;
      if (p > 0) h -= p * std::log(p);
    }
  }
  return h;
}

double centre_brightness(const Image& img, const Eigen::Vector2d& centre, double radius_px) {
  if (img.empty()) return 0.0;
  const cv::Scalar mean = cv::mean(wrap(img), disc_mask(img, centre, radius_px));
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

}  // namespace omniloc
