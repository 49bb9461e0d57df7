// The sensor model and the optics before it (see photometry.hpp). Units: DN, ms, seconds, metres,
// radians; frames: image pixels for the output, render space in GL order for the read-back.
//
// This file is compiled with -fno-math-errno (CMakeLists.txt) for expose_row: the square root's
// argument is never negative, and without errno the loop vectorises.
#include "sim/render/photometry.hpp"

#include <algorithm>
#include <cmath>

namespace omniloc::sim {

namespace {

// Pixel noise: standard normals kept in 1/32 steps from -4 to +4 (one byte each); the step is a
// thirtieth of a DN at the largest noise (about 5 DN), well below the output's rounding.
constexpr double kNoiseStep = 1.0 / 32.0;
constexpr double kNoiseZero = 127.5;  // index of 0 (halfway, so the steps are symmetric)
constexpr std::size_t kNoiseTable = std::size_t{1} << 20;
// Each sub-frame is a full draw of the scene.
constexpr int kMaxSubframes = 3;

// One row of the sensor: value = radiance * per_unit (DN), plus noise of std
// sqrt(var_read + var_shot * min(255, value)) times a standard normal from the noise table (steps
// of kNoiseStep around kNoiseZero), rounded and clipped.
void expose_row(const float* rad, const std::uint8_t* nz, std::uint8_t* out, int n, float per_unit, float var_read, float var_shot) {
  const float step = static_cast<float>(kNoiseStep), zero = static_cast<float>(kNoiseZero);
  for (int i = 0; i < n; ++i) {
    const float mean = rad[i] * per_unit;
    const float sigma = std::sqrt(var_read + var_shot * (mean < 255.0f ? mean : 255.0f));
    float val = mean + sigma * ((static_cast<float>(nz[i]) - zero) * step) + 0.5f;
    val = val < 0.0f ? 0.0f : (val > 255.0f ? 255.0f : val);
    out[i] = static_cast<std::uint8_t>(static_cast<int>(val));
  }
}

}  // namespace

Photometry::Photometry(const CameraConfig& cfg, const MirrorProfile& mirror, int ss)
    : cfg_(cfg), ss_(ss), W_(cfg.width * ss), H_(cfg.height * ss), centre_(cfg.mirror_centre_px()), rim_(mirror.rim()) {
  // Defocus (docs/camera.md "Optical blur"): the camera focuses on the mirror's virtual image at
  // focus_radius; elsewhere the virtual image lies off the focused surface by a depth that grows
  // with the squared image radius (a curved image surface), so the blur circle's diameter is
  // b(r) = optical_blur_px |r^2 - rf^2| / (rim^2 - rf^2); a uniform disc of diameter b has a
  // per-axis std of b / 4, used as the Gaussian's sigma.
  if (cfg_.optical_blur_px > 0) {
    const double rim = mirror.rim(), rf = cfg_.focus_radius_fraction * rim;
    const int n = static_cast<int>(std::ceil(rim * ss_)) + 2;
    std::vector<double> sigma(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      const double r = static_cast<double>(i) / ss_;
      sigma[static_cast<std::size_t>(i)] = ss_ * 0.25 * cfg_.optical_blur_px * std::fabs(r * r - rf * rf) / (rim * rim - rf * rf);
    }
    defocus_ = std::make_unique<RadialDefocus>(W_, H_, centre_ * ss_, rim * ss_, sigma);
  }
  if (cfg_.motion_blur) {
    smear_ = std::make_unique<RotationSmear>(W_, H_, centre_ * ss_, mirror.rim() * ss_);
    translation_ = std::make_unique<TranslationBlur>(W_, H_, ss_, centre_, mirror, cfg_.mount_height);
  }
  // The floor's finest sampling sets how many sub-frames an exposure of a moving robot needs.
  finest_floor_m_per_px_ = 1e9;
  for (double r = mirror.body_radius(); r + 1.0 <= mirror.rim(); r += 1.0) {
    const double e0 = mirror.elevation(r), e1 = mirror.elevation(r + 1.0);
    if (e1 >= -1e-6) break;
    finest_floor_m_per_px_ = std::min(finest_floor_m_per_px_, cfg_.mount_height / std::tan(-e1) - cfg_.mount_height / std::tan(-e0));
  }
}

void Photometry::draw_noise_table(Rng& rng) {
  if (!noise_.empty()) return;
  // 2^20 standard normals, stored as steps of kNoiseStep (index kNoiseZero = 0), plus a copy of
  // the first row's worth at the end, so that a row's samples are one contiguous run of the table
  // (a strided walk of a float table missed the cache on every sample).
  const std::size_t n = kNoiseTable;
  noise_.resize(n + 3 * static_cast<std::size_t>(cfg_.width));
  for (std::size_t i = 0; i < n; ++i)
    noise_[i] = static_cast<std::uint8_t>(std::clamp(std::lround(kNoiseZero + rng.normal() / kNoiseStep), 0L, 255L));
  std::copy(noise_.begin(), noise_.begin() + static_cast<std::ptrdiff_t>(noise_.size() - n), noise_.begin() + static_cast<std::ptrdiff_t>(n));
}

// One sub-frame per pixel of smear at the floor's finest sampling, at most kMaxSubframes.
int Photometry::subframes(double speed, double exposure_s) const {
  if (!(exposure_s > 0)) return 1;
  const double px = speed * exposure_s / finest_floor_m_per_px_;
  return std::clamp(static_cast<int>(std::ceil(px)), 1, kMaxSubframes);
}

void Photometry::clear_sum() { accumulate_.assign(static_cast<std::size_t>(W_) * H_ * 4, 0u); }

void Photometry::add_subframe() {
  std::uint32_t* a = accumulate_.data();
  const std::uint16_t* s = subframe_.data();
  for (std::size_t i = 0; i < subframe_.size(); ++i) a[i] += s[i];
}

// The mean rounded half up: (sum + n / 2) / n for n = 2 and 3, as a vectorised multiply (the
// integer division per value cost 3 ms a frame).
void Photometry::average(int subframes) {
  readback16_.resize(accumulate_.size());
  const float inv = 1.0f / static_cast<float>(subframes);
  const std::uint32_t* a = accumulate_.data();
  std::uint16_t* o = readback16_.data();
  for (std::size_t i = 0; i < accumulate_.size(); ++i) o[i] = static_cast<std::uint16_t>(static_cast<float>(a[i]) * inv + 0.5f);
}

void Photometry::translation_blur(const Eigen::Vector2d& velocity, const std::vector<double>& taus) {
  if (!translation_) return;
  translation_->apply(Rgba16View{readback16_.data(), W_, H_}, depth_, velocity, taus);
}

void Photometry::apply_optics(double turn) {
  const Rgba16View view{readback16_.data(), W_, H_};
  if (smear_) smear_->apply(view, turn);
  if (defocus_) defocus_->apply(view);
}

// Per pixel and channel from the full 16 bits (a table by 8-bit GL level, the way until photometry
// v3, put steps of up to 8 DN into a dimly lit carpet once exposure and gain were raised).
Image Photometry::expose(const CameraSettings& st, std::uint64_t offset) {
  const int samples = ss_ * ss_;
  const float per_unit = static_cast<float>(kRadianceScale / 65535.0 / samples * kResponse * st.exposure_ms * st.gain);
  const float gainf = static_cast<float>(st.gain / 18.0);
  const float var_read = static_cast<float>(cfg_.read_noise * cfg_.read_noise) * gainf * gainf;
  const float var_shot = static_cast<float>(cfg_.shot_noise * cfg_.shot_noise) * gainf;
  Image img;
  img.width = cfg_.width;
  img.height = cfg_.height;
  img.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
  const std::size_t mask = kNoiseTable - 1;
  std::size_t k = offset & mask;
  const Eigen::Vector2d c = centre_;
  const double rim = rim_;
  std::fill(img.rgb.begin(), img.rgb.end(), std::uint8_t{0});  // outside the mirror: black
  std::vector<float>& radiance = row_radiance_;
  for (int v = 0; v < img.height; ++v) {
    // The span of this row inside the mirror rim.
    const double dv = v + 0.5 - c.y();
    if (std::fabs(dv) >= rim) continue;
    const double half = std::sqrt(rim * rim - dv * dv);
    const int u0 = std::max(0, static_cast<int>(std::ceil(c.x() - half - 0.5)));
    const int u1 = std::min(img.width - 1, static_cast<int>(std::floor(c.x() + half - 0.5)));
    if (u1 < u0) continue;
    const int n = 3 * (u1 - u0 + 1);
    radiance.resize(static_cast<std::size_t>(n));
    const std::uint16_t* r0 = &readback16_[static_cast<std::size_t>(H_ - 1 - v * ss_) * W_ * 4];  // GL rows bottom-up
    if (ss_ == 1) {
      for (int u = u0; u <= u1; ++u)
        for (int ch = 0; ch < 3; ++ch) radiance[static_cast<std::size_t>(3 * (u - u0) + ch)] = r0[u * 4 + ch];
    } else {
      const std::uint16_t* r1 = r0 - static_cast<std::ptrdiff_t>(W_) * 4;
      for (int u = u0; u <= u1; ++u)
        for (int ch = 0; ch < 3; ++ch) {
          const int a = (2 * u) * 4 + ch, b = a + 4;
          radiance[static_cast<std::size_t>(3 * (u - u0) + ch)] = static_cast<float>(r0[a] + r0[b] + r1[a] + r1[b]);
        }
    }
    const std::uint8_t* nz = &noise_[k];
    std::uint8_t* out = img.row(v) + 3 * u0;
    const float* rad = radiance.data();
    expose_row(rad, nz, out, n, per_unit, var_read, var_shot);
    k = (k + static_cast<std::size_t>(n)) & mask;
  }
  return img;
}

}  // namespace omniloc::sim
