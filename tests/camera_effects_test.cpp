// What makes the simulated camera a real robot's camera (docs/camera.md "What a real camera adds"): the measured NuBot mirror,
// motion blur over the exposure, defocus towards the rim, tilt from acceleration, and lamp light
// without 8-bit banding. Truth-side tests: they use the simulator's own projection.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::sim;
using scenes::one_robot;
using scenes::mean_abs_diff;
using scenes::mean_image;
using scenes::quiet_camera;

TEST(MirrorPresets, NubotTanFollowsTheMeasuredLaw) {
  CameraConfig cfg = quiet_camera();
  cfg.mirror = "nubot_tan";
  PanoramicCamera cam(cfg, Field::preset("msl2012"));
  const double rim = cam.rim_px(), b = kPi / (2 * rim), a = 1.6768;
  // d(r) = a tan(b r) with the horizon at the rim (nubot_ws calib_results/2/mirror_calib.xml, scaled).
  for (double r : {60.0, 100.0, 150.0, 200.0, 250.0, 290.0}) {
    const auto p = cam.floor_point(cam.centre().x(), cam.centre().y() - r);  // straight ahead
    ASSERT_TRUE(p) << r;
    EXPECT_NEAR(p->norm(), a * std::tan(b * r), 2e-3 * a * std::tan(b * r)) << "radius " << r;
  }
  // The body hides the floor within 0.44 m (NuBot's small_radius of 38 px at b = 0.0067311).
  EXPECT_NEAR(a * std::tan(b * cam.body_radius_px()), 0.4385, 1e-3);
  // Floor per pixel at 1, 4, 6, 8 m: 1.14, 5.6, 11.6, 20.0 cm (docs/camera.md's nubot_tan column for this rim).
  const double cm[] = {1.14, 5.62, 11.6, 20.0};
  int i = 0;
  for (double d : {1.0, 4.0, 6.0, 8.0}) {
    const double r = (*cam.project({d, 0, 0}) - cam.centre()).norm();
    const double per_px = (*cam.floor_point(cam.centre().x(), cam.centre().y() - r - 0.5) - *cam.floor_point(cam.centre().x(), cam.centre().y() - r + 0.5)).norm();
    EXPECT_NEAR(100 * per_px, cm[i], 0.02 * cm[i]) << d << " m";
    ++i;
  }
}

TEST(CameraEffects, RotationBlurIsTheExposureIntegral) {
  // A robot spinning at 6 rad/s with a 6 ms exposure: the image must equal the mean of the sharp
  // images over headings theta - omega s, s in [0, T] (a smear of omega T = 0.036 rad, 11 px at
  // the rim), and not one with half or twice the width or the other direction.
  const Field field = Field::preset("msl2012");
  CameraConfig blur_cfg = quiet_camera();
  blur_cfg.motion_blur = true;
  PanoramicCamera blurred(blur_cfg, field), sharp(quiet_camera(), field);
  const double omega = 6.0, T = 0.006, theta = 0.4;  // a fast turn: 0.036 rad, 11 px at the rim
  // Exposed so that nothing clips (lines below 160 DN): the sensor integrates light, the reference
  // here averages 8-bit images, which agree only where no pixel saturated.
  const CameraSettings st{6.0, 18.0};
  WorldState w = one_robot(Pose2(-1.5, -1.0, theta));
  w.robots[0].omega = omega;
  Rng rng(1);
  const Image img = blurred.render(w, 0, st, rng);
  auto integral = [&](double width) {
    const int n = 48;
    return mean_image(n, [&](int k) {
      Rng r(1);
      return sharp.render(one_robot(Pose2(-1.5, -1.0, theta - width * (k + 0.5) / n)), 0, st, r);
    });
  };
  const Eigen::Vector2d c = blurred.centre();
  const double lo = blurred.body_radius_px() + 2, hi = blurred.rim_px() - 2;
  const Image ex = integral(omega * T);
  const double exact = mean_abs_diff(img, ex, c, lo, hi);
  const double half = mean_abs_diff(img, integral(0.5 * omega * T), c, lo, hi);
  const double twice = mean_abs_diff(img, integral(2.0 * omega * T), c, lo, hi);
  const double reversed = mean_abs_diff(img, integral(-omega * T), c, lo, hi);
  Rng r0(1);
  const double none = mean_abs_diff(img, sharp.render(w, 0, st, r0), c, lo, hi);
  std::printf("mean |difference| to the exposure integral %.3f DN; to sharp %.3f, half width %.3f, twice %.3f, reversed %.3f\n", exact, none, half, twice, reversed);
  EXPECT_LT(exact, 0.35 * none) << "exact " << exact << " sharp " << none;
  EXPECT_LT(exact, 0.5 * half);
  EXPECT_LT(exact, 0.5 * twice);
  EXPECT_LT(exact, 0.3 * reversed);
  // A robot that does not turn or move is not blurred at all.
  w.robots[0].omega = 0;
  Rng a(1), b(1);
  EXPECT_EQ(blurred.render(w, 0, st, a).rgb, sharp.render(w, 0, st, b).rgb);
}

TEST(CameraEffects, TranslationBlurAveragesSubframes) {
  // Driving at 3 m/s for 20 ms moves the floor by 6 cm: near the body (0.5 cm per pixel) that is
  // many pixels, so the moving robot's image differs from the standing one near the body, little far out.
  const Field field = Field::preset("msl2012");
  CameraConfig cfg = quiet_camera();
  cfg.motion_blur = true;
  PanoramicCamera cam(cfg, field);
  WorldState w = one_robot(Pose2(-1.5, -1.0, 0.4));
  Rng a(1), b(1);
  const CameraSettings st{20.0, 18.0};
  const Image still = cam.render(w, 0, st, a);
  w.robots[0].velocity = {3.0 * std::cos(0.4), 3.0 * std::sin(0.4)};
  const Image moving = cam.render(w, 0, st, b);
  EXPECT_NE(still.rgb, moving.rgb);
  Rng c(1);
  EXPECT_EQ(moving.rgb, cam.render(w, 0, st, c).rgb);  // deterministic
}

TEST(CameraEffects, DefocusGrowsTowardsTheRim) {
  const Field field = Field::preset("msl2012");
  CameraConfig cfg = quiet_camera();
  cfg.optical_blur_px = 3.0;
  cfg.focus_radius_fraction = 0.5;
  PanoramicCamera blurred(cfg, field), sharp(quiet_camera(), field);
  const WorldState w = one_robot(Pose2(-1.0, -2.0, 0.3));
  Rng a(1), b(1);
  const Image bi = blurred.render(w, 0, {}, a), si = sharp.render(w, 0, {}, b);
  const Eigen::Vector2d c = sharp.centre();
  const double rim = sharp.rim_px();
  const double at_focus = mean_abs_diff(bi, si, c, 0.45 * rim, 0.55 * rim);
  const double at_rim = mean_abs_diff(bi, si, c, 0.85 * rim, 0.97 * rim);
  EXPECT_LT(at_focus, 0.3);  // sigma under 0.1 px in focus: at most rounding
  EXPECT_GT(at_rim, 5 * std::max(at_focus, 0.05));
}

TEST(CameraEffects, AccelerationTiltsTheCamera) {
  // Accelerating to the robot's left at 2 m/s^2 with 0.25 deg per m/s^2 rolls the camera by 0.5 deg:
  // the same pixels as a mirror mounted with 0.5 deg of roll on a robot at rest.
  const Field field = Field::preset("msl2012");
  CameraConfig tilting = quiet_camera();
  tilting.tilt_per_accel = deg2rad(0.25);
  CameraConfig mounted = quiet_camera();
  mounted.mirror_tilt = deg2rad(0.5);
  PanoramicCamera cam(tilting, field), ref(mounted, field), plain(quiet_camera(), field);
  const double theta = 0.7;
  WorldState w = one_robot(Pose2(-1.0, -2.0, theta));
  w.robots[0].acceleration = Eigen::Vector2d(-std::sin(theta), std::cos(theta)) * 2.0;  // robot-frame (0, 2)
  Rng a(1), b(1), c(1);
  const Image tilted = cam.render(w, 0, {}, a);
  EXPECT_EQ(tilted.rgb, ref.render(one_robot(Pose2(-1.0, -2.0, theta)), 0, {}, b).rgb);
  EXPECT_NE(tilted.rgb, plain.render(w, 0, {}, c).rgb);
}

TEST(CameraEffects, LampLightFallsWithoutBanding) {
  // Half the hall's lamps off and exposure control's answer to the dark (60 ms, gain 30): the
  // carpet's light changes smoothly across the floor, so neighbouring carpet pixels differ by the
  // light's slope only (with an 8-bit framebuffer one GL level was ~7 DN here: steps of 7-8 DN).
  const Field field = Field::preset("msl2012");
  PanoramicCamera cam(quiet_camera(), field);
  WorldState w = one_robot(Pose2(0.5, -1.5, 0.2));
  w.lighting.level = 0.35;
  for (double x : {-6.0, -2.0, 2.0, 6.0}) w.lighting.lamps.push_back({Eigen::Vector2d(x, 0.0), 3.0, x < 0 ? 0.0 : 1.0});
  const CameraSettings st{60.0, 30.0};
  Rng rng(1);
  const Image img = cam.render(w, 0, st, rng);
  const Image lab = cam.render_labels(w, 0);
  // Within 8 m of floor (0.8 of the rim), where every line is 3 px wide and its pixels are labelled
  // line: beyond, a line thinner than a pixel tints carpet-labelled pixels.
  int worst = 0, pairs = 0, carpet_max = 0;
  const double r_max = 0.8 * cam.rim_px();
  for (int v = 0; v < img.height; ++v)
    for (int u = 2; u + 2 < img.width; ++u) {
      if ((Eigen::Vector2d(u + 1.0, v + 0.5) - cam.centre()).norm() > r_max) continue;
      bool field_run = true;
      for (int k = -2; k <= 2; ++k) field_run = field_run && lab.row(v)[3 * (u + k)] == kLabelField;
      if (!field_run) continue;
      const int g0 = img.row(v)[3 * u + 1], g1 = img.row(v)[3 * (u + 1) + 1];
      if (g0 >= 250 || g1 >= 250) continue;
      // Where lines cross, the distance field's kink spreads a line's tint past its labelled pixels:
      // white raises red with green, the light's slope moves green alone (carpet red is ~1/4 of green).
      if (std::abs(img.row(v)[3 * u] - img.row(v)[3 * (u + 1)]) > 4) continue;
      carpet_max = std::max(carpet_max, g0);
      worst = std::max(worst, std::abs(g0 - g1));
      ++pairs;
    }
  ASSERT_GT(pairs, 10000);
  EXPECT_GT(carpet_max, 120);  // the carpet is exposed well, not dark
  EXPECT_LE(worst, 3) << "neighbouring carpet pixels differ by up to " << worst << " DN";
}
