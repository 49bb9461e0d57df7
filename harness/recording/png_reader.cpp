#include "harness/recording/png_reader.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.hpp"

namespace omniloc::harness {

std::shared_ptr<const Image> read_png(const std::string& path) {
  const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  // The file was found readable before (why_not_readable_file): what fails here is its content.
  if (bgr.empty()) throw ConfigError(path, "no image OpenCV can read", "a PNG image (recording.json says \"images\": true)");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  auto img = std::make_shared<Image>();
  img->width = rgb.cols;
  img->height = rgb.rows;
  img->rgb.assign(rgb.data, rgb.data + static_cast<std::size_t>(rgb.cols) * rgb.rows * 3);
  return img;
}

}  // namespace omniloc::harness
