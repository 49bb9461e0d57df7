#include "sim/render/image_blur.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/angles.hpp"

namespace omniloc::sim {

namespace {

// OpenCV's pixel-index coordinates (pixel centres at integers, rows as stored, i.e. bottom-up) of a
// render-space point (pixel centres at +0.5, y down).
cv::Point2f to_buffer(int height, const Eigen::Vector2d& p) {
  return {static_cast<float>(p.x() - 0.5), static_cast<float>(height - p.y() - 0.5)};
}

// Image motion over the whole exposure below which a pixel keeps the mid-exposure render.
constexpr double kStillPx = 1.0;

}  // namespace

namespace {

// One bilinear sample of an RGBA16 image at (fx, fy) (pixel-index units, the border replicated), as
// 4 floats: the 4 channels. `stride` in uint16 per row.
struct Rgba4 {
#if defined(__SSE2__)
  __m128 v;
#else
  float v[4];
#endif
};

inline Rgba4 sample_rgba16(const std::uint16_t* base, std::size_t stride, int w, int h, float fx, float fy) {
  const float fxc = std::clamp(fx, 0.0f, static_cast<float>(w - 1)), fyc = std::clamp(fy, 0.0f, static_cast<float>(h - 1));
  const int x0 = std::min(static_cast<int>(fxc), std::max(w - 2, 0)), y0 = std::min(static_cast<int>(fyc), std::max(h - 2, 0));
  const float ax = fxc - static_cast<float>(x0), ay = fyc - static_cast<float>(y0);
  const std::uint16_t* p0 = base + static_cast<std::size_t>(y0) * stride + 4 * static_cast<std::size_t>(x0);
  const std::uint16_t* p1 = p0 + (h > 1 ? stride : 0);
  const std::size_t dx = w > 1 ? 4 : 0;
  Rgba4 out;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  auto load = [&](const std::uint16_t* p) { return _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), zero)); };
  const __m128 a0 = load(p0), b0 = load(p1);
  const __m128 top = _mm_add_ps(a0, _mm_mul_ps(_mm_set1_ps(ax), _mm_sub_ps(load(p0 + dx), a0)));
  const __m128 bot = _mm_add_ps(b0, _mm_mul_ps(_mm_set1_ps(ax), _mm_sub_ps(load(p1 + dx), b0)));
  out.v = _mm_add_ps(top, _mm_mul_ps(_mm_set1_ps(ay), _mm_sub_ps(bot, top)));
#else
  for (int ch = 0; ch < 4; ++ch) {
    const float top = p0[ch] + ax * (static_cast<float>(p0[dx + ch]) - p0[ch]);
    const float bot = p1[ch] + ax * (static_cast<float>(p1[dx + ch]) - p1[ch]);
    out.v[ch] = top + ay * (bot - top);
  }
#endif
  return out;
}

// v * scale + 0.5, truncated to uint16 (values in 0 ... 65535 / scale), into o[0..3].
inline void store_rgba16(const Rgba4& v, float scale, std::uint16_t* o) {
#if defined(__SSE2__)
  const __m128i iv = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(v.v, _mm_set1_ps(scale)), _mm_set1_ps(0.5f)));
  // 4 x int32 (0 ... 65535) to uint16 without SSE4.1's packus: bias to signed and back.
  const __m128i packed = _mm_xor_si128(_mm_packs_epi32(_mm_sub_epi32(iv, _mm_set1_epi32(32768)), _mm_setzero_si128()), _mm_set1_epi16(-32768));
  _mm_storel_epi64(reinterpret_cast<__m128i*>(o), packed);
#else
  for (int ch = 0; ch < 4; ++ch) o[ch] = static_cast<std::uint16_t>(v.v[ch] * scale + 0.5f);
#endif
}

inline Rgba4 add_rgba(const Rgba4& a, const Rgba4& b) {
  Rgba4 out;
#if defined(__SSE2__)
  out.v = _mm_add_ps(a.v, b.v);
#else
  for (int ch = 0; ch < 4; ++ch) out.v[ch] = a.v[ch] + b.v[ch];
#endif
  return out;
}

}  // namespace

void remap_rgba16(const cv::Mat& src, const cv::Mat& map, cv::Mat& dst) {
  CV_Assert(src.type() == CV_16UC4 && map.type() == CV_32FC2 && src.data != dst.data);
  dst.create(map.rows, map.cols, CV_16UC4);
  const std::size_t stride = src.step1();  // uint16 per row
  const std::uint16_t* base = src.ptr<std::uint16_t>(0);
  cv::parallel_for_(cv::Range(0, map.rows), [&](const cv::Range& rows) {  // rows alone: any partition gives the same bytes
    for (int y = rows.start; y < rows.end; ++y) {
      const float* m = map.ptr<float>(y);
      std::uint16_t* o = dst.ptr<std::uint16_t>(y);
      for (int x = 0; x < map.cols; ++x) store_rgba16(sample_rgba16(base, stride, src.cols, src.rows, m[2 * x], m[2 * x + 1]), 1.0f, o + 4 * x);
    }
  });
}

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
  cv::merge(std::vector<cv::Mat>{px, py}, to_polar_);
  cv::Mat bx(height, width, CV_32FC1), by(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double dx = x - centre_.x, dy = y - centre_.y;
      double phi = std::atan2(dy, dx);
      if (phi < 0) phi += 2.0 * kPi;
      bx.at<float>(y, x) = static_cast<float>(std::hypot(dx, dy));
      by.at<float>(y, x) = static_cast<float>(phi * na_ / (2.0 * kPi));
    }
  cv::merge(std::vector<cv::Mat>{bx, by}, from_polar_);
}

void RotationSmear::apply(const Rgba16View& img, double angle) {
  if (std::fabs(angle) * rim_ < 0.05) return;
  cv::Mat src(img.height, img.width, CV_16UC4, img.data);
  remap_rgba16(src, to_polar_, polar_);
  // The box average over `d` rows from each row's cell boundary: n whole cells and a fraction of
  // the next, kept as running sums per column and channel. A positive render-space angle is
  // clockwise in the stored (bottom-up) buffer, i.e. towards lower rows.
  const double d = std::fabs(angle) * na_ / (2.0 * kPi);
  const int n = static_cast<int>(std::floor(d));
  const double frac = d - n;
  const int step = angle > 0 ? -1 : 1;
  const int w = nr_ * 4;
  auto row = [&](int i) { return polar_.ptr<std::uint16_t>(((i % na_) + na_) % na_); };
  // Exact integer running sums (a double per element took most of the smear's time); the window's
  // mean in float, rounded.
  sum_.assign(static_cast<std::size_t>(w), 0u);
  for (int k = 0; k < n; ++k) {
    const std::uint16_t* r = row(step * k);
    for (int x = 0; x < w; ++x) sum_[static_cast<std::size_t>(x)] += r[x];
  }
  const float fracf = static_cast<float>(frac), inv_d = static_cast<float>(1.0 / d);
  smeared_.create(na_ + 1, nr_, CV_16UC4);  // + row 0 again: remap reads across the 2 pi seam
  std::uint32_t* sum = sum_.data();
  for (int i = 0; i < na_; ++i) {
    const int start = step * i;  // walk the rows in the smear's direction so the running sum stays a window
    const std::uint16_t* tail = row(start + step * n);
    std::uint16_t* o = smeared_.ptr<std::uint16_t>(((start % na_) + na_) % na_);
    for (int x = 0; x < w; ++x) {
      const float v = (static_cast<float>(sum[x]) + fracf * static_cast<float>(tail[x])) * inv_d + 0.5f;
      o[x] = static_cast<std::uint16_t>(v < 65535.0f ? v : 65535.0f);
    }
    const std::uint16_t* first = row(start);
    for (int x = 0; x < w; ++x) sum[x] = sum[x] + tail[x] - first[x];
  }
  smeared_.row(0).copyTo(smeared_.row(na_));
  remap_rgba16(smeared_, from_polar_, back_);
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
  y0_ = std::clamp(static_cast<int>(std::floor(c.y - rim)), 0, height);
  y1_ = std::clamp(static_cast<int>(std::ceil(c.y + rim)) + 1, y0_, height);
  c1_.assign(static_cast<std::size_t>(width) * height, 0.0f);
  c2_.assign(c1_.size(), 0.0f);
  for (int y = y0_; y < y1_; ++y)
    for (int x = 0; x < width; ++x) {
      const double r = std::hypot(x - c.x, y - c.y);
      if (r > rim) continue;
      const double ri = std::min(r, static_cast<double>(n - 1));
      const std::size_t i0 = static_cast<std::size_t>(ri), i1 = std::min(n - 1, i0 + 1);
      const double s = sigma_by_radius[i0] + (ri - static_cast<double>(i0)) * (sigma_by_radius[i1] - sigma_by_radius[i0]);
      const double q = std::clamp(2.0 * s / sigma_max_, 0.0, 2.0);  // in level units: 0 sharp, 1 half, 2 full
      const std::size_t k = static_cast<std::size_t>(y) * width + x;
      c1_[k] = static_cast<float>(std::min(q, 1.0));
      c2_[k] = static_cast<float>(std::max(q - 1.0, 0.0));
    }
  // The full level is needed only where c2 > 0 (sigma above sigma_max / 2: near the rim, and near
  // the centre when the focus ring is far out): bands of 64 rows, in each the runs of columns where
  // any pixel has c2 > 0. The blur of such a rectangle reads its neighbours from the whole image.
  constexpr int kBand = 64;
  for (int b0 = y0_; b0 < y1_; b0 += kBand) {
    const int b1 = std::min(y1_, b0 + kBand);
    std::vector<bool> col(static_cast<std::size_t>(width), false);
    for (int y = b0; y < b1; ++y)
      for (int x = 0; x < width; ++x)
        if (c2_[static_cast<std::size_t>(y) * width + x] > 0.0f) col[static_cast<std::size_t>(x)] = true;
    for (int x = 0; x < width;) {
      if (!col[static_cast<std::size_t>(x)]) {
        ++x;
        continue;
      }
      const int xs = x;
      while (x < width && col[static_cast<std::size_t>(x)]) ++x;
      full_rects_.emplace_back(xs, b0, x - xs, b1 - b0);
    }
  }
  full_.create(height, width, CV_32FC4);
  full_.setTo(cv::Scalar::all(0));  // finite where never blurred: c2 = 0 there
  // Per row, the columns inside the rim (outside it c1 = c2 = 0: the pixel stays).
  span_.assign(static_cast<std::size_t>(height), {0, 0});
  for (int y = y0_; y < y1_; ++y) {
    const double dy = y - c.y;
    if (dy * dy > rim * rim) continue;
    const double half = std::sqrt(rim * rim - dy * dy);
    const int x0 = std::clamp(static_cast<int>(std::floor(c.x - half)) - 1, 0, width), x1 = std::clamp(static_cast<int>(std::ceil(c.x + half)) + 2, x0, width);
    span_[static_cast<std::size_t>(y)] = {x0, x1};
  }
}

void RadialDefocus::apply(const Rgba16View& img) {
  if (!active()) return;
  // In float: OpenCV's Gaussian on 16-bit data is its bit-exact fixed-point path, twice as slow as
  // the vectorised float one; the two agree to a fraction of one 16-bit unit.
  cv::Mat src(img.height, img.width, CV_16UC4, img.data);
  src.convertTo(src_f_, CV_32FC4);
  auto blur = [&](double sigma, cv::Mat& out) { cv::GaussianBlur(src_f_, out, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE); };
  blur(0.5 * sigma_max_, half_);
  for (const cv::Rect& rc : full_rects_) {
    cv::Mat out = full_(rc);
    cv::GaussianBlur(src_f_(rc), out, cv::Size(0, 0), sigma_max_, sigma_max_, cv::BORDER_REPLICATE);
  }
  // Each pixel blends the two levels around its own sigma: I + c1 (half - I) + c2 (full - half),
  // (c1, c2) = (q, 0) below level 1 and (1, q - 1) above it; outside the rim (0, 0) keeps the pixel.
  // Rows in parallel (OpenCV's pool): every pixel is computed alone, so the bytes do not depend on
  // the partition or the thread count.
  cv::parallel_for_(cv::Range(y0_, y1_), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      std::uint16_t* o = src.ptr<std::uint16_t>(y);
      const float* a = src_f_.ptr<float>(y);
      const float* h = half_.ptr<float>(y);
      const float* f = full_.ptr<float>(y);
      const float* c1 = &c1_[static_cast<std::size_t>(y) * width_];
      const float* c2 = &c2_[static_cast<std::size_t>(y) * width_];
      const auto [x0, x1] = span_[static_cast<std::size_t>(y)];
      for (int x = x0; x < x1; ++x) {
        // A convex combination of the levels (c2 <= c1 <= 1): no clipping needed.
        Rgba4 v;
  #if defined(__SSE2__)
        const __m128 av = _mm_loadu_ps(a + 4 * x), hv = _mm_loadu_ps(h + 4 * x), fv = _mm_loadu_ps(f + 4 * x);
        v.v = _mm_add_ps(_mm_add_ps(av, _mm_mul_ps(_mm_set1_ps(c1[x]), _mm_sub_ps(hv, av))), _mm_mul_ps(_mm_set1_ps(c2[x]), _mm_sub_ps(fv, hv)));
  #else
        for (int ch = 0; ch < 4; ++ch) v.v[ch] = a[4 * x + ch] + c1[x] * (h[4 * x + ch] - a[4 * x + ch]) + c2[x] * (f[4 * x + ch] - h[4 * x + ch]);
  #endif
        store_rgba16(v, 1.0f, o + 4 * x);
      }
    }
  });
}

TranslationBlur::TranslationBlur(int width, int height, int ss, const Eigen::Vector2d& centre, const MirrorProfile& mirror, double mount_height)
    : width_(width), height_(height) {
  const cv::Point2f c = to_buffer(height, centre * ss);
  cx_ = c.x;
  cy_ = c.y;
  r_min_ = static_cast<float>((mirror.body_radius() + 1.0) * ss);
  r_max_ = static_cast<float>((mirror.rim() - 1.0) * ss);
  const std::size_t n = static_cast<std::size_t>(width) * height;
  m_.assign(4 * n, 0.0f);
  inv_floor_.assign(n, 0.0f);
  for (int yb = 0; yb < height; ++yb)
    for (int xb = 0; xb < width; ++xb) {
      // Image pixels, render space (y down), relative to the axis.
      const double dx = (xb + 0.5) / ss - centre.x(), dy = (height - yb - 0.5) / ss - centre.y();
      const double r = std::hypot(dx, dy);
      if (r < mirror.body_radius() + 0.5 || r > mirror.rim()) continue;
      const double e = mirror.elevation(r), de = 1e-5;
      const double slope = (mirror.radius(e + de) - mirror.radius(e - de)) / (2.0 * de);  // R'(e), px / rad
      // The projection puts robot-frame direction (ux, uy) at image offset -r (uy, ux) / |u| (render
      // space); a point at distance D moving at -v turns the radius at A (u.v) / D and the bearing
      // at B (u x v) / D (times -1 / r), A = R'(e) sin e, B = r / cos e (buffer pixels). In the
      // buffer (x right, rows up) that is the 2 x 2 matrix below, times 1 / D.
      const double ux = -dy / r, uy = -dx / r;
      const double A = ss * slope * std::sin(e), B = std::cos(e) > 1e-3 ? ss * r / std::cos(e) : 0.0;
      const std::size_t k = static_cast<std::size_t>(yb) * width + xb;
      m_[4 * k + 0] = static_cast<float>(-(A + B) * ux * uy);
      m_[4 * k + 1] = static_cast<float>(B * ux * ux - A * uy * uy);
      m_[4 * k + 2] = static_cast<float>(A * ux * ux - B * uy * uy);
      m_[4 * k + 3] = static_cast<float>((A + B) * ux * uy);
      inv_floor_[k] = static_cast<float>(e < -1e-6 ? std::sin(-e) / mount_height : 0.0);
    }
  // The rows and, per row, the columns that hold the mirror's ring.
  span_.assign(static_cast<std::size_t>(height), {0, 0});
  for (int yb = 0; yb < height; ++yb) {
    int x0 = width, x1 = 0;
    for (int xb = 0; xb < width; ++xb) {
      const std::size_t k = static_cast<std::size_t>(yb) * width + xb;
      if (m_[4 * k] != 0.0f || m_[4 * k + 1] != 0.0f || m_[4 * k + 2] != 0.0f || m_[4 * k + 3] != 0.0f) {
        x0 = std::min(x0, xb);
        x1 = std::max(x1, xb + 1);
      }
    }
    span_[static_cast<std::size_t>(yb)] = {x0, std::max(x0, x1)};
  }
}

void TranslationBlur::apply(const Rgba16View& img, const std::vector<float>& depth, const Eigen::Vector2d& velocity,
                            const std::vector<double>& taus) {
  if (taus.size() < 2) return;
  CV_Assert(depth.size() == static_cast<std::size_t>(width_) * height_ && img.width == width_ && img.height == height_);
  const float vx = static_cast<float>(velocity.x()), vy = static_cast<float>(velocity.y());
  // The exposure's length from the sub-frames' times (centred on their intervals): a pixel whose
  // image moves less than kStillPx over it keeps the render (see the header).
  const auto [tmin, tmax] = std::minmax_element(taus.begin(), taus.end());
  const double span = (*tmax - *tmin) * static_cast<double>(taus.size()) / static_cast<double>(taus.size() - 1);
  const float still2 = static_cast<float>(kStillPx * kStillPx / std::max(span * span, 1e-30));  // |u|^2 below this: still
  const float r_min2 = r_min_ * r_min_, r_max2 = r_max_ * r_max_, inv_n = 1.0f / static_cast<float>(taus.size());
  std::vector<float> t(taus.begin(), taus.end());
  const std::size_t stride = static_cast<std::size_t>(width_) * 4;
  const std::uint16_t* base = img.data;
  // Pass 1 reads the render only: the moving pixels' means go to a side list...
  moved_.resize(static_cast<std::size_t>(height_));
  // Rows in parallel (OpenCV's pool), each with its own list and velocity buffers: a pixel's value
  // depends on the render only, not on the partition or the thread count.
  cv::parallel_for_(cv::Range(0, height_), [&](const cv::Range& rows) {
    std::vector<float> row_u(static_cast<std::size_t>(width_)), row_v(static_cast<std::size_t>(width_));
    for (int y = rows.start; y < rows.end; ++y) {
      std::vector<Moved>& list = moved_[static_cast<std::size_t>(y)];
      list.clear();
      const auto [x0, x1] = span_[static_cast<std::size_t>(y)];
      const std::size_t k0 = static_cast<std::size_t>(y) * width_;
      // The image velocity of the row's pixels (a loop the compiler vectorises), then the moving ones.
      float* __restrict ru = row_u.data();
      float* __restrict rv = row_v.data();
      const float* __restrict dep = depth.data() + k0;
      const float* __restrict invf = inv_floor_.data() + k0;
      const float* __restrict mm = m_.data() + 4 * k0;
      for (int x = x0; x < x1; ++x) {
        const float dz = dep[x];
        const float inv_d = dz < 1.0f ? 0.001f / (dz > 1e-6f ? dz : 1e-6f) : invf[x];
        ru[x] = inv_d * (mm[4 * x] * vx + mm[4 * x + 1] * vy);  // buffer px / s
        rv[x] = inv_d * (mm[4 * x + 2] * vx + mm[4 * x + 3] * vy);
      }
      for (int x = x0; x < x1; ++x) {
        const std::size_t k = k0 + x;
        const float u = ru[x], v = rv[x];
        if (u * u + v * v < still2) continue;
        Rgba4 acc{};
        for (std::size_t j = 0; j < t.size(); ++j) {
          if (t[j] == 0.0f) {  // the render itself (the middle sub-frame of an odd count)
            const Rgba4 s = sample_rgba16(base, stride, width_, height_, static_cast<float>(x), static_cast<float>(y));
            acc = j == 0 ? s : add_rgba(acc, s);
            continue;
          }
          float mx = static_cast<float>(x) - t[j] * u, my = static_cast<float>(y) - t[j] * v;
          // Keep the sample on the mirror's floor ring: off the body, inside the rim.
          const float ex = mx - cx_, ey = my - cy_, r2 = ex * ex + ey * ey;
          if (r2 < r_min2 || r2 > r_max2) {
            const float scale = (r2 < r_min2 ? r_min_ : r_max_) / std::sqrt(std::max(r2, 1e-12f));
            mx = cx_ + ex * scale;
            my = cy_ + ey * scale;
          }
          const Rgba4 s = sample_rgba16(base, stride, width_, height_, mx, my);
          acc = j == 0 ? s : add_rgba(acc, s);
        }
        Moved mv;
        mv.index = static_cast<std::uint32_t>(k);
        store_rgba16(acc, inv_n, mv.value);
        list.push_back(mv);
      }
    }
  });
  // ... and pass 2 writes them.
  for (const std::vector<Moved>& list : moved_)
    for (const Moved& mv : list) std::copy(mv.value, mv.value + 4, img.data + 4 * static_cast<std::size_t>(mv.index));
}

}  // namespace omniloc::sim
