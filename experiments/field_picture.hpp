#pragma once
// Top-down pictures of the field (world frame, x right, y up) for experiments' figures: the
// markings drawn from the field model, and helpers to place world points in the picture.
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/field.hpp"

namespace omniloc::experiments {

class FieldPicture {
 public:
  /// `px_per_m`: scale; `border`: metres of floor shown beyond the field's outer lines.
  FieldPicture(const Field& field, double px_per_m = 30.0, double border = 1.2);
  /// Pixel of a world point (metres).
  cv::Point px(const Eigen::Vector2d& w) const;
  cv::Point px(double x, double y) const { return px(Eigen::Vector2d(x, y)); }
  double scale() const { return s_; }
  /// A fresh copy of the background (green floor, white markings), BGR.
  cv::Mat canvas() const { return bg_.clone(); }

 private:
  double s_, x0_, y0_;
  cv::Mat bg_;
};

/// Encodes a BGR picture as PNG into a byte string (for RunDirectory::write).
std::string png_bytes(const cv::Mat& bgr);

}  // namespace omniloc::experiments
