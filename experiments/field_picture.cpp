#include "experiments/field_picture.hpp"

#include <cmath>


#include "core/error.hpp"
#include "harness/image_file.hpp"

namespace omniloc::experiments {

FieldPicture::FieldPicture(const Field& field, double px_per_m, double border) : s_(px_per_m) {
  const double hx = 0.5 * field.length + border, hy = 0.5 * field.width + border;
  x0_ = -hx;
  y0_ = hy;
  const int w = static_cast<int>(std::ceil(2 * hx * s_)), h = static_cast<int>(std::ceil(2 * hy * s_));
  bg_ = cv::Mat(h, w, CV_8UC3, cv::Scalar(60, 130, 60));
  // Markings from the exact distance function, so the picture is the model the localizers use.
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const Eigen::Vector2d p(x0_ + (c + 0.5) / s_, y0_ - (r + 0.5) / s_);
      if (field.distance_to_marking(p) <= 0.5 * field.line_width + 0.5 / s_) bg_.at<cv::Vec3b>(r, c) = cv::Vec3b(235, 235, 235);
    }
}

cv::Point FieldPicture::px(const Eigen::Vector2d& w) const {
  return {static_cast<int>(std::lround((w.x() - x0_) * s_)), static_cast<int>(std::lround((y0_ - w.y()) * s_))};
}

std::string png_bytes(const cv::Mat& bgr) { return harness::encode_png(bgr); }

}  // namespace omniloc::experiments
