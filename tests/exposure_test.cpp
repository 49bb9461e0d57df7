#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.hpp"
#include "localization/vision/entropy.hpp"
#include "localization/vision/exposure_control.hpp"

using namespace omniloc;

namespace {
Image constant(int w, int h, std::uint8_t v) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgb.assign(static_cast<std::size_t>(w) * h * 3, v);
  return img;
}

ExposureParams enabled() {
  ExposureParams p;
  p.enabled = true;
  p.search_at_start = false;  // the tests below script the lighting change themselves
  return p;
}

// Runs the controller against a scene whose entropy along the search line is `h(gain)` and whose
// body brightness is `b(t)`; returns the frame index the search ended on (or -1).
template <class H, class B>
int drive(ExposureController& c, H h, B b, int frames, double rate = 30.0) {
  for (int k = 0; k < frames; ++k) {
    const double t = k / rate;
    const double e = c.wants_entropy() ? h(c.current().gain) : -1.0;
    const ExposureDecision d = c.update(t, b(t), e);
    if (d.event && d.event->rfind("search_end", 0) == 0) return k;
  }
  return -1;
}
}  // namespace

TEST(Entropy, ConstantImageHasNone) {
  EXPECT_DOUBLE_EQ(image_entropy(constant(64, 48, 137)), 0.0);
  EXPECT_DOUBLE_EQ(image_entropy(constant(64, 48, 0)), 0.0);
}

TEST(Entropy, UniformNoiseIsThreeLn256) {
  Image img = constant(640, 640, 0);
  Rng rng(1);
  for (auto& v : img.rgb) v = static_cast<std::uint8_t>(rng.uniform_index(256));
  // 409600 samples per channel in 256 bins: the plug-in estimate is low by about 255 / (2 N).
  EXPECT_NEAR(image_entropy(img), 3.0 * std::log(256.0), 0.01);
}

TEST(Entropy, TwoEqualHalvesGiveLn2PerChannel) {
  Image img = constant(100, 100, 10);
  for (std::size_t i = 0; i < img.rgb.size() / 2; ++i) img.rgb[i] = 200;
  EXPECT_NEAR(image_entropy(img), 3.0 * std::log(2.0), 1e-12);
}

TEST(Entropy, MaskedDiscAndCentreBrightness) {
  Image img = constant(100, 100, 50);
  for (int v = 40; v < 60; ++v)
    for (int u = 40; u < 60; ++u)
      for (int c = 0; c < 3; ++c) img.row(v)[3 * u + c] = 250;
  EXPECT_NEAR(centre_brightness(img, {50, 50}, 8), 250.0, 1e-9);
  EXPECT_DOUBLE_EQ(image_entropy(img, {50, 50}, 8), 0.0);  // only the bright square inside the disc
  EXPECT_GT(image_entropy(img), 0.0);
}

TEST(ExposureControl, FindsThePeakOfAUnimodalCurveInFewSteps) {
  for (double peak : {7.3, 12.0, 18.0, 26.6}) {
    ExposureController c(enabled(), CameraSettings{18.0, 18.0});
    double level = 100.0;
    auto b = [&](double t) { return t < 0.2 ? 100.0 : level; };
    level = peak < 18 ? 160.0 : 60.0;  // brighter scene: the peak moved down, and vice versa
    const int end = drive(c, [&](double g) { return 10.0 - 0.01 * (g - peak) * (g - peak); }, b, 400);
    ASSERT_GE(end, 0) << "peak " << peak;
    EXPECT_NEAR(c.current().gain, peak, 0.5) << "peak " << peak;
    EXPECT_DOUBLE_EQ(c.current().exposure_ms, c.current().gain);  // on the line exposure = 1 * gain + 0
    EXPECT_LE(c.steps_last_search(), 14) << "peak " << peak;
  }
}

TEST(ExposureControl, ALightingChangeIsDetectedWithinAFewFramesASteadySceneNever) {
  ExposureController c(enabled(), CameraSettings{18.0, 18.0});
  Rng noise(3);
  int start = -1;
  for (int k = 0; k < 300; ++k) {
    const double t = k / 30.0;
    const double body = (k < 200 ? 120.0 : 190.0) + noise.normal(0.0, 2.0);  // lamps change at frame 200
    const ExposureDecision d = c.update(t, body, c.wants_entropy() ? 10.0 : -1.0);
    if (d.event && d.event->rfind("search_start", 0) == 0) {
      start = k;
      break;
    }
    EXPECT_FALSE(d.searching) << "frame " << k;
  }
  EXPECT_GE(start, 200);
  EXPECT_LE(start, 203);
}

TEST(ExposureControl, EachSettingCostsTheSettleTimeAndTheRobotStops) {
  ExposureParams p = enabled();
  p.settle_s = 0.04;  // longer than one frame at 30 Hz: every new setting skips a frame
  ExposureController c(p, CameraSettings{18.0, 18.0});
  int searching_frames = 0, measured = 0;
  for (int k = 0; k < 300; ++k) {
    const double t = k / 30.0;
    const bool want = c.wants_entropy();
    const ExposureDecision d = c.update(t, k < 3 ? 100.0 : 40.0, want ? 10.0 - 0.01 * (c.current().gain - 30) * (c.current().gain - 30) : -1.0);
    searching_frames += d.searching;
    if (d.event && d.event->rfind("search_end", 0) == 0) break;
    (void)measured;
  }
  EXPECT_GE(searching_frames, 2 * c.steps_last_search());
}

TEST(ExposureControl, ASearchOutsideTheCameraRangeIsClampedWithAWarningAndEnds) {
  ExposureParams p = enabled();
  p.gain_max = 30.0;
  p.exposure_max = 30.0;
  ExposureController c(p, CameraSettings{18.0, 18.0});
  int warnings = 0, end = -1;
  for (int k = 0; k < 1000 && end < 0; ++k) {
    const double t = k / 30.0;
    const double e = c.wants_entropy() ? 10.0 - 0.001 * (c.current().gain - 80) * (c.current().gain - 80) : -1.0;  // peak beyond the range
    const ExposureDecision d = c.update(t, k < 3 ? 150.0 : 20.0, e);
    warnings += static_cast<int>(d.warnings.size());
    if (d.event && d.event->rfind("search_end", 0) == 0) end = k;
  }
  ASSERT_GE(end, 0);
  EXPECT_GT(warnings, 0);
  EXPECT_DOUBLE_EQ(c.current().gain, 30.0);
  EXPECT_LE(c.steps_last_search(), p.max_steps);
}

TEST(ExposureControl, AFlatCurveStopsAtTheStepBoundNeverLoops) {
  ExposureParams p = enabled();
  p.max_steps = 6;
  ExposureController c(p, CameraSettings{18.0, 18.0});
  int end = drive(c, [](double g) { return 10.0 + 1e-3 * g; }, [](double t) { return t < 0.2 ? 100.0 : 10.0; }, 1000);  // rises forever
  ASSERT_GE(end, 0);
  EXPECT_LE(c.steps_last_search(), 6);
}

TEST(ExposureControl, DisabledNeverChangesTheSettings) {
  ExposureParams p;  // enabled = false
  ExposureController c(p, CameraSettings{18.0, 18.0});
  for (int k = 0; k < 100; ++k) {
    const ExposureDecision d = c.update(k / 30.0, k < 50 ? 100.0 : 250.0, -1.0);
    EXPECT_FALSE(d.searching);
    EXPECT_DOUBLE_EQ(d.settings.gain, 18.0);
  }
}

TEST(ExposureControl, SearchesOnceAtStartByDefault) {
  ExposureParams p;
  p.enabled = true;  // search_at_start defaults to true: the robot adjusts once when it starts
  ExposureController c(p, CameraSettings{18.0, 18.0});
  const int end = drive(c, [](double g) { return 10.0 - 0.01 * (g - 12.0) * (g - 12.0); }, [](double) { return 200.0; }, 300);
  ASSERT_GE(end, 0);
  EXPECT_NEAR(c.current().gain, 12.0, 0.5);
  EXPECT_EQ(c.searches(), 1);
  for (int k = end + 1; k < end + 200; ++k) EXPECT_FALSE(c.update(k / 30.0, 200.0, -1.0).searching);  // steady afterwards
}

TEST(ExposureControl, LightChangingDuringTheSearchStartsAnother) {
  // The lamps go off at 2 s and, while the robot searches, come back over 0.5 s (lighting_002_lamps
  // does this at 40 s). The entropies the search compared were taken under changing light, so its
  // result is measured under light that is gone; the body at the chosen setting then does not look
  // as it did when that setting was measured, and a new search under the steady light must follow.
  // Scene model: body brightness and the entropy peak follow light x exposure x gain (exposure = gain).
  ExposureParams p = enabled();
  ExposureController c(p, CameraSettings{18.0, 18.0});
  auto light = [](double t) { return t < 2.0 ? 1.0 : (t < 2.3 ? 0.3 : std::min(1.0, 0.3 + 0.7 * (t - 2.3) / 0.5)); };
  bool restarted = false;
  for (int k = 0; k < 400; ++k) {
    const double t = k / 30.0, l = light(t), g = c.current().gain;
    const double body = std::min(255.0, 120.0 * l * g * g / (18.0 * 18.0));
    const double peak = 18.0 / std::sqrt(l);
    const ExposureDecision d = c.update(t, body, c.wants_entropy() ? 10.0 - 0.01 * (g - peak) * (g - peak) : -1.0);
    if (d.event && d.event->find("light changed during the search") != std::string::npos) restarted = true;
  }
  EXPECT_TRUE(restarted);
  EXPECT_NEAR(c.current().gain, 18.0, 1.0);  // the peak under the returned light
}
