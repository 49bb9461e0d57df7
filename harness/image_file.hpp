#pragma once
// PNG and JPEG files through libpng and libjpeg(-turbo) directly. OpenCV's imgcodecs did this before,
// but Debian builds it against GDAL, GDCM, Poppler, HDF5 and a hundred more libraries that every start
// of omniloc loaded (142 shared objects, about 50 ms of each process's start, which the tests pay
// thousands of times). The two codecs are what imgcodecs itself calls; the settings below are
// OpenCV 4.6's, so every file written is byte for byte the one cv::imencode wrote, and every image
// read has the pixels cv::imread(IMREAD_COLOR) gave (tests/image_file_test.cpp checks both against
// OpenCV on every PNG colour type and bit depth).
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "core/messages.hpp"

namespace omniloc::harness {

/// A PNG of an 8-bit image: 1 channel (grey), 3 (BGR, OpenCV's order) or 4 (BGRA). OpenCV's default
/// settings: SUB filter, zlib level 1, RLE strategy. Throws RuntimeFailure for another type.
std::string encode_png(const cv::Mat& image);

/// A baseline JPEG of an 8-bit grey or BGR image at `quality` (1..100): libjpeg's defaults, as
/// cv::imencode(".jpg", image, {IMWRITE_JPEG_QUALITY, quality}).
std::string encode_jpeg(const cv::Mat& image, int quality);

/// The PNG file at `path` as an RGB image, whatever its colour type and bit depth: palette and grey
/// expanded, alpha dropped, 16 bits cut to their high byte (what cv::imread(IMREAD_COLOR) gives).
/// Throws ConfigError(path, what libpng said, a PNG image) when the content is not a PNG it can read.
Image read_png_rgb(const std::string& path);

}  // namespace omniloc::harness
