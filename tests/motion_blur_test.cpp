// How the field_robot camera effects are computed since commit 2b91411 (docs/camera.md "What a real camera
// adds", "How the effects are computed"): the translation blur resampled from one render, defocus
// in float, the rotation smear's own bilinear resampler. Each is compared with what it replaced:
// the re-rendered sub-frames, and the code of commit 5e4c5e1 (copied below as the reference), on
// the same buffers. Tolerances are stated where they are asserted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "sim/render/image_blur.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "sim/render/photometry.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::sim;
using scenes::one_robot;
using scenes::mean_abs_diff;
using scenes::mean_image;
using scenes::quiet_camera;

namespace {

// A radiance buffer with structure at every scale: carpet, 3 px lines every 37 px both ways, a
// few discs, values up to 60000.
std::vector<std::uint16_t> test_pattern(int w, int h) {
  std::vector<std::uint16_t> buf(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool line = (x % 37) < 3 || (y % 37) < 3;
      const bool disc = std::hypot((x % 101) - 50, (y % 89) - 44) < 9;
      std::uint16_t* p = &buf[(static_cast<std::size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint16_t>(line ? 58000 : disc ? 9000 : 4000 + 7 * x);
      p[1] = static_cast<std::uint16_t>(line ? 60000 : disc ? 30000 : 20000 + 5 * y);
      p[2] = static_cast<std::uint16_t>(line ? 57000 : disc ? 45000 : 6000);
      p[3] = 65535;
    }
  return buf;
}

// The defocus of commit 5e4c5e1 (RadialDefocus before commit 2b91411): OpenCV's fixed-point Gaussian on
// the 16-bit buffer at sigma_max / 2 and sigma_max, blended per pixel in 1/65536 steps.
void old_defocus(std::vector<std::uint16_t>& buf, int w, int h, const Eigen::Vector2d& centre, double rim, const std::vector<double>& sigma) {
  const double sigma_max = *std::max_element(sigma.begin(), sigma.end());
  const cv::Point2f c(static_cast<float>(centre.x() - 0.5), static_cast<float>(h - centre.y() - 0.5));
  cv::Mat src(h, w, CV_16UC4, buf.data()), half, full;
  cv::GaussianBlur(src, half, cv::Size(0, 0), 0.5 * sigma_max, 0.5 * sigma_max, cv::BORDER_REPLICATE);
  cv::GaussianBlur(src, full, cv::Size(0, 0), sigma_max, sigma_max, cv::BORDER_REPLICATE);
  const cv::Mat src_copy = src.clone();
  const cv::Mat* levels[3] = {&src_copy, &half, &full};
  const std::size_t n = sigma.size();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double r = std::hypot(x - c.x, y - c.y);
      if (r > rim) continue;
      const double ri = std::min(r, static_cast<double>(n - 1));
      const std::size_t i0 = static_cast<std::size_t>(ri), i1 = std::min(n - 1, i0 + 1);
      const double s = sigma[i0] + (ri - static_cast<double>(i0)) * (sigma[i1] - sigma[i0]);
      const double q = std::clamp(2.0 * s / sigma_max, 0.0, 2.0);
      const int lo = std::min(1, static_cast<int>(q));
      const std::uint32_t wb = static_cast<std::uint32_t>(std::lround(std::min(65535.0, (q - lo) * 65536.0))), wa = 65536u - wb;
      const std::uint16_t* a = levels[lo]->ptr<std::uint16_t>(y) + 4 * x;
      const std::uint16_t* b = levels[lo + 1]->ptr<std::uint16_t>(y) + 4 * x;
      for (int ch = 0; ch < 3; ++ch) src.ptr<std::uint16_t>(y)[4 * x + ch] = static_cast<std::uint16_t>((wa * a[ch] + wb * b[ch] + 32768u) >> 16);
    }
}

}  // namespace

TEST(CameraEffectsCost, TranslationBlurIsTheExposureIntegral) {
  // The observer drives at 2 m/s with a 6 ms exposure (1.2 cm: 15 px at the body's edge, 0.3 px at
  // 1 m and beyond): 3 sub-frames. The image resampled from one render must be as close to the true
  // exposure integral (the mean of 48 sharp renders over [t - T, t]) as the 3 re-rendered sub-frames
  // it replaced (the mean of 3 sharp renders at their times), and close to those.
  const Field field = Field::preset("msl2012");
  CameraConfig blur_cfg = quiet_camera();
  blur_cfg.motion_blur = true;
  PanoramicCamera blurred(blur_cfg, field), sharp(quiet_camera(), field);
  const double speed = 2.0, T = 0.006, theta = 0.4;
  const Eigen::Vector2d v(speed * std::cos(theta), speed * std::sin(theta));
  const Pose2 at_t(-1.5, -1.0, theta);
  const CameraSettings st{6.0, 18.0};  // nothing clips: the references average 8-bit images
  WorldState w = one_robot(at_t);
  w.robots[0].velocity = v;
  Rng rng(1);
  const Image img = blurred.render(w, 0, st, rng);
  auto mean_of = [&](int n, double sign) {
    return mean_image(n, [&](int k) {
      const double back = sign * T * (1.0 - (k + 0.5) / n);
      Rng r(1);
      return sharp.render(one_robot(Pose2(at_t.x - back * v.x(), at_t.y - back * v.y(), theta)), 0, st, r);
    });
  };
  const Eigen::Vector2d c = blurred.centre();
  const double lo = blurred.body_radius_px() + 2, hi = blurred.rim_px() - 2;
  const Image integral = mean_of(48, 1.0), subframes = mean_of(3, 1.0), reversed = mean_of(48, -1.0);
  Rng r0(1);
  const Image still = sharp.render(w, 0, st, r0);
  const double to_integral = mean_abs_diff(img, integral, c, lo, hi);
  const double old_to_integral = mean_abs_diff(subframes, integral, c, lo, hi);
  const double to_old = mean_abs_diff(img, subframes, c, lo, hi);
  const double to_sharp = mean_abs_diff(img, still, c, lo, hi);
  const double to_reversed = mean_abs_diff(img, reversed, c, lo, hi);
  // Within 1 m (the body's edge to 110 px), where the motion is large, and beyond it.
  const double near_new = mean_abs_diff(img, integral, c, lo, 110), near_old = mean_abs_diff(subframes, integral, c, lo, 110);
  std::printf("mean |difference| to the exposure integral: resampled %.3f DN, 3 re-rendered sub-frames %.3f DN (within 1 m: %.3f, %.3f); "
              "resampled to re-rendered %.3f; to sharp %.3f; to the reversed motion %.3f\n",
              to_integral, old_to_integral, near_new, near_old, to_old, to_sharp, to_reversed);
  // Resampling is not re-rendering: bilinear samples soften (most where the sub-frames lie a few
  // pixels apart, near the body) and the samples at the body's edge are the floor at the edge. It
  // stays within 0.1 DN of the integral on average and 0.15 DN within 1 m (the re-rendered
  // sub-frames: 0.006 and 0.03 DN), a twentieth of the blur's own effect there.
  EXPECT_LT(to_integral, 0.1);
  EXPECT_LT(near_new, 0.15);
  EXPECT_LT(near_new, 0.1 * mean_abs_diff(still, integral, c, lo, 110));
  EXPECT_LT(to_old, 0.1) << "the stated tolerance: resampled vs re-rendered sub-frames, mean |difference| DN";
  EXPECT_LT(to_integral, 0.2 * to_sharp);
  EXPECT_LT(to_integral, 0.1 * to_reversed);
}

TEST(CameraEffectsCost, OtherMoversStillReRender) {
  // Another robot moving: its own motion is not in the observer's image-motion field, so the
  // sub-frames are drawn again (the path before commit 2b91411); deterministic either way.
  const Field field = Field::preset("msl2012");
  CameraConfig cfg = quiet_camera();
  cfg.motion_blur = true;
  PanoramicCamera cam(cfg, field);
  WorldState w = one_robot(Pose2(-1.5, -1.0, 0.4));
  w.robots[0].velocity = {1.0, 0.5};
  RobotState other;
  other.id = 1;
  other.pose = Pose2(-0.5, -0.6, 0.0);
  w.robots.push_back(other);
  const CameraSettings st{20.0, 18.0};
  Rng a(1), b(1), c(1);
  const Image resampled = cam.render(w, 0, st, a);
  w.robots[1].velocity = {0.0, 3.0};
  const Image rerendered = cam.render(w, 0, st, b);
  EXPECT_NE(resampled.rgb, rerendered.rgb);
  EXPECT_EQ(rerendered.rgb, cam.render(w, 0, st, c).rgb);
}

TEST(CameraEffectsCost, DefocusAgreesWithTheFixedPointVersion) {
  // Float Gaussians and a float blend against the 16-bit fixed-point code they replaced, on the
  // same buffer with the field_robot blur (2.5 px at the rim, focus at half the rim) at 4x the
  // defocus of field_robot so that every level matters. Tolerance: 3 units of 65535 at most (the
  // 16-bit buffer's rounding; 0.2 DN at exposure 18 ms, gain 18), under 0.5 on average.
  const int w = 640, h = 640;
  const Eigen::Vector2d centre(326.4, 313.6);
  const double rim = 313.6;
  std::vector<double> sigma(static_cast<std::size_t>(std::ceil(rim)) + 2);
  for (std::size_t i = 0; i < sigma.size(); ++i) {
    const double r = static_cast<double>(i), rf = 0.5 * rim;
    sigma[i] = 4 * 0.25 * 2.5 * std::fabs(r * r - rf * rf) / (rim * rim - rf * rf);
  }
  std::vector<std::uint16_t> a = test_pattern(w, h), b = a;
  RadialDefocus(w, h, centre, rim, sigma).apply(Rgba16View{a.data(), w, h});
  old_defocus(b, w, h, centre, rim, sigma);
  int worst = 0;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    const int d = std::abs(static_cast<int>(a[i]) - static_cast<int>(b[i]));
    worst = std::max(worst, d);
    sum += d;
    ++n;
  }
  std::printf("defocus, float vs fixed point: max %d, mean %.3f (16-bit units)\n", worst, sum / static_cast<double>(n));
  EXPECT_LE(worst, 3);
  EXPECT_LT(sum / static_cast<double>(n), 0.5);
}

TEST(CameraEffectsCost, RemapMatchesOpenCv) {
  // remap_rgba16 (float weights, SSE2) against cv::remap (1/32-pixel fixed-point weights) on a
  // rotation by 0.1 rad with a shift: they differ by OpenCV's quantisation of the weights to 1/32
  // (up to 1/64 per axis), i.e. at most 1/32 of the largest step between neighbours (54000 units
  // at a line's edge: 1690), and little on average.
  const int w = 640, h = 640;
  const std::vector<std::uint16_t> buf = test_pattern(w, h);
  const cv::Mat src(h, w, CV_16UC4, const_cast<std::uint16_t*>(buf.data()));
  cv::Mat map(h, w, CV_32FC2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double dx = x - 320.0, dy = y - 320.0;
      map.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(320.0 + std::cos(0.1) * dx - std::sin(0.1) * dy + 0.37),
                                          static_cast<float>(320.0 + std::sin(0.1) * dx + std::cos(0.1) * dy - 0.21));
    }
  cv::Mat ours, theirs;
  remap_rgba16(src, map, ours);
  cv::remap(src, theirs, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  double sum = 0;
  int worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 4 * w; ++x) {
      const int d = std::abs(static_cast<int>(ours.ptr<std::uint16_t>(y)[x]) - static_cast<int>(theirs.ptr<std::uint16_t>(y)[x]));
      sum += d;
      worst = std::max(worst, d);
    }
  const double mean = sum / (4.0 * w * h);
  std::printf("remap_rgba16 vs cv::remap: max %d, mean %.2f (16-bit units)\n", worst, mean);
  EXPECT_LT(worst, 54000 / 32 + 2);
  EXPECT_LT(mean, 40.0);
}
