#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "core/field.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {
using scenes::quiet_camera;
using scenes::one_robot;
}  // namespace

class CameraTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { cam_ = new PanoramicCamera(quiet_camera(), Field::preset("msl2012")); }
  static void TearDownTestSuite() {
    delete cam_;
    cam_ = nullptr;
  }
  static PanoramicCamera* cam_;
};
PanoramicCamera* CameraTest::cam_ = nullptr;

TEST_F(CameraTest, ProjectionRoundTripsThroughTheFloor) {
  for (double d : {0.5, 1.0, 2.0, 4.0, 6.0, 7.9})
    for (double b : {0.0, 0.7, 2.0, -2.5}) {
      const Eigen::Vector3d p(d * std::cos(b), d * std::sin(b), 0.0);
      const auto px = cam_->project(p);
      ASSERT_TRUE(px) << d << " " << b;
      const auto back = cam_->floor_point(px->x(), px->y());
      ASSERT_TRUE(back);
      EXPECT_NEAR((*back - p.head<2>()).norm(), 0.0, 1e-3) << "distance " << d;
    }
  // Forward is up in the image, left is left.
  const auto ahead = cam_->project({2.0, 0.0, 0.0});
  const auto left = cam_->project({0.0, 2.0, 0.0});
  EXPECT_LT(ahead->y(), cam_->centre().y() - 50);
  EXPECT_NEAR(ahead->x(), cam_->centre().x(), 1e-6);
  EXPECT_LT(left->x(), cam_->centre().x() - 50);
  // The isometric part: image radius linear in floor distance between 1 m and 8 m.
  const double r2 = (*cam_->project({2.0, 0, 0}) - cam_->centre()).norm();
  const double r4 = (*cam_->project({4.0, 0, 0}) - cam_->centre()).norm();
  const double r6 = (*cam_->project({6.0, 0, 0}) - cam_->centre()).norm();
  EXPECT_NEAR(r6 - r4, r4 - r2, 0.05);
}

// Every pixel of the floor shows the floor point the mirror puts there. The floor mesh's vertices
// used to carry their floor points and the rasteriser interpolated them across each cell, but the
// floor position is not affine in the image (it holds D(r) p / |p|), so across the long cells of the
// mirror's isometric part lines were drawn up to 1 cm nearer the robot at 1-2 m than they lie.
// Labels are drawn where a pixel centre's floor point is within half a line width of a marking's
// centre line: compare them with the truth's floor point of the same pixel centre, leaving out
// pixels within 3 mm of a line's edge (the distance field's 2 cm texels are exact only to a
// fraction of a millimetre across straight edges, less at arcs and corners).
TEST_F(CameraTest, FloorLinesLieWhereTheMirrorPutsThem) {
  const Field field = Field::preset("msl2012");
  int checked = 0, wrong = 0;
  for (const Pose2& pose : {Pose2(-4.0, -1.0, 0.3), Pose2(1.5, 2.0, -1.1), Pose2(3.0, -2.5, 2.4), Pose2(-1.0, 0.7, 0.0)}) {
    const Image labels = cam_->render_labels(one_robot(pose), 0);
    for (int v = 0; v < labels.height; ++v)
      for (int u = 0; u < labels.width; ++u) {
        const auto fp = cam_->floor_point(u + 0.5, v + 0.5);
        if (!fp || fp->norm() < 0.5 || fp->norm() > 4.0) continue;
        const std::uint8_t c = labels.row(v)[3 * u];
        if (c != kLabelLine && c != kLabelField) continue;
        const double d = field.distance_to_marking(pose.transform(*fp)) - 0.5 * field.line_width;
        if (std::abs(d) < 0.003) continue;
        ++checked;
        wrong += (c == kLabelLine) != (d < 0);
      }
  }
  ASSERT_GT(checked, 50000);
  std::printf("floor pixels 0.5-4 m: %d checked, %d with the wrong class\n", checked, wrong);
  EXPECT_LT(wrong, checked / 10000);  // before: 295 of 314490
}

TEST_F(CameraTest, SameStateGivesIdenticalPixels) {
  const WorldState w = one_robot(Pose2(1.0, -2.0, 0.4));
  Rng a(5), b(5);
  const Image i1 = cam_->render(w, 0, {}, a);
  const Image i2 = cam_->render(w, 0, {}, b);
  EXPECT_EQ(i1.rgb, i2.rgb);
}

TEST_F(CameraTest, LinesAreWhiteAndARobotHidesThem) {
  // Observer at (0, -2) facing +x: the centre line x = 0 runs through the robot's left and right.
  WorldState w = one_robot(Pose2(-1.0, -2.0, 0.0));
  const Eigen::Vector3d on_line(1.0, 0.0, 0.0);  // robot frame: 1 m ahead lies on x = 0
  const auto px = cam_->project(on_line);
  ASSERT_TRUE(px);
  Image lab = cam_->render_labels(w, 0);
  auto label_at = [&](const Image& im, const Eigen::Vector2d& p) { return im.row(static_cast<int>(p.y()))[3 * static_cast<int>(p.x())]; };
  EXPECT_EQ(label_at(lab, *px), kLabelLine);
  Rng rng(1);
  const Image col = cam_->render(w, 0, {}, rng);
  const std::uint8_t* c = col.row(static_cast<int>(px->y())) + 3 * static_cast<int>(px->x());
  EXPECT_GT(c[0], 150);  // white
  // Another robot between camera and line hides it.
  RobotState other;
  other.id = 1;
  other.pose = Pose2(-0.45, -2.0, 0.0);
  w.robots.push_back(other);
  lab = cam_->render_labels(w, 0);
  EXPECT_EQ(label_at(lab, *px), kLabelObstacle);
}

TEST_F(CameraTest, FarLineStaysContinuous) {
  // The goal line x = 9 seen from (3, 0) facing +x: 6 m away. Walk along it in the label image.
  const WorldState w = one_robot(Pose2(3.0, 0.0, 0.0));
  const Image lab = cam_->render_labels(w, 0);
  int gaps = 0;
  for (double y = -5.5; y <= 5.5; y += 0.1) {
    if (std::fabs(y) < 1.3) continue;  // the goal posts and net stand on the line there
    const auto px = cam_->project({6.0, y, 0.0});
    ASSERT_TRUE(px);
    bool found = false;
    for (int dv = -2; dv <= 2 && !found; ++dv)
      for (int du = -2; du <= 2 && !found; ++du)
        found = lab.row(static_cast<int>(px->y()) + dv)[3 * (static_cast<int>(px->x()) + du)] == kLabelLine;
    gaps += !found;
  }
  EXPECT_EQ(gaps, 0);
}

// The floor's anti-aliasing keeps a line's light: summed over a radial profile across the side
// line y = -6, the pixels' line coverage (from the green channel, read between carpet and white)
// times each pixel's floor extent gives the line's width, whether the line is 3 px wide (6.5 m,
// the isometric part) or under a pixel (9.5 m, beyond 8 m where a pixel spans decimetres).
TEST_F(CameraTest, AntiAliasingKeepsTheLineWidth) {
  CameraSettings st;
  st.exposure_ms = 12;  // white below the clip
  st.gain = 12;
  const double carpet = PanoramicCamera::response(0.34, 1.0, st), white = PanoramicCamera::response(0.85, 1.0, st);
  ASSERT_LT(white, 250.0);
  const Field field = Field::preset("msl2012");
  for (double ahead : {6.5, 9.5}) {
    // Facing -y from (2, ahead - 6): the side line lies `ahead` metres straight ahead (up in the
    // image, one pixel column), away from every other marking.
    const WorldState w = one_robot(Pose2(2.0, ahead - 6.0, -kPi / 2));
    Rng rng(1);
    const Image img = cam_->render(w, 0, st, rng);
    const auto px = cam_->project({ahead, 0.0, 0.0});
    ASSERT_TRUE(px);
    const int u = static_cast<int>(px->x()), v0 = static_cast<int>(px->y());
    double width = 0.0, peak = 0.0;
    for (int v = v0 - 8; v <= v0 + 8; ++v) {
      const auto near = cam_->floor_point(u + 0.5, v + 1.0), far = cam_->floor_point(u + 0.5, v);
      if (!near || !far || near->x() < ahead - 1.5 || far->x() > ahead + 0.9) continue;  // the wall stands 1 m beyond the line
      const double cover = (img.row(v)[3 * u + 1] - carpet) / (white - carpet);
      width += cover * (far->x() - near->x());
      peak = std::max(peak, cover);
    }
    std::printf("line %.1f m ahead: width %.4f m from the profile, peak coverage %.2f\n", ahead, width, peak);
    EXPECT_NEAR(width, field.line_width, 0.1 * field.line_width) << "line " << ahead << " m ahead";
    if (ahead > 8) {
      EXPECT_LT(peak, 0.9) << "a line under a pixel is blended with the carpet";
    }
  }
}

TEST_F(CameraTest, ExposureSaturatesAndNoiseGrowsWithGain) {
  const WorldState w = one_robot(Pose2(0.0, -3.0, 0.0));
  Rng rng(2);
  const Image normal = cam_->render(w, 0, {18.0, 18.0}, rng);
  const Image bright = cam_->render(w, 0, {60.0, 60.0}, rng);
  std::size_t sat_n = 0, sat_b = 0;
  for (std::size_t i = 0; i < normal.rgb.size(); ++i) {
    sat_n += normal.rgb[i] == 255;
    sat_b += bright.rgb[i] == 255;
  }
  // Photometry v2 (entropy peak at 18 / 18): the white lines and goals clip, the carpet does not.
  EXPECT_LT(sat_n, normal.rgb.size() / 20);
  EXPECT_GT(sat_b, normal.rgb.size() / 5);    // over-exposed: the carpet's green clips too
  EXPECT_NEAR(PanoramicCamera::response(0.85, 1.0, {18, 18}), 450.0, 1e-9);
  EXPECT_LT(PanoramicCamera::response(0.34, 1.0, {18, 18}), 255.0);  // the carpet green channel (albedo 0.34)

  CameraConfig noisy = quiet_camera();
  noisy.read_noise = 2.0;
  noisy.shot_noise = 0.5;
  PanoramicCamera cam(noisy, Field::preset("msl2012"));
  auto noise_std = [&](double gain) {
    Rng r1(3), r2(4);
    const Image a = cam.render(w, 0, {324.0 / gain, gain}, r1), b = cam.render(w, 0, {324.0 / gain, gain}, r2);
    double s2 = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) s2 += std::pow(double(a.rgb[i]) - double(b.rgb[i]), 2);
    return std::sqrt(s2 / a.rgb.size() / 2.0);
  };
  const double low = noise_std(6.0), high = noise_std(54.0);  // same brightness, different gain
  EXPECT_GT(low, 0.5);
  EXPECT_GT(high, 2.0 * low);
}

namespace {
// Mean RGB over a 3 x 3 block around the image point of a robot-frame 3-D point.
Eigen::Vector3d rgb_at(const PanoramicCamera& cam, const Image& im, const Eigen::Vector3d& robot_point) {
  const auto px = cam.project(robot_point);
  EXPECT_TRUE(px);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) {
      const std::uint8_t* c = im.row(static_cast<int>(px->y()) + dv) + 3 * (static_cast<int>(px->x()) + du);
      sum += Eigen::Vector3d(c[0], c[1], c[2]);
    }
  return sum / 9.0;
}
// HSV hue in degrees and saturation in [0, 1].
double hue_deg(const Eigen::Vector3d& c) {
  const double mx = c.maxCoeff(), mn = c.minCoeff(), d = mx - mn;
  if (d <= 0) return 0.0;
  double h = mx == c[0] ? std::fmod((c[1] - c[2]) / d, 6.0) : mx == c[1] ? (c[2] - c[0]) / d + 2.0 : (c[0] - c[1]) / d + 4.0;
  return 60.0 * (h < 0 ? h + 6.0 : h);
}
double saturation(const Eigen::Vector3d& c) { return c.maxCoeff() > 0 ? 1.0 - c.minCoeff() / c.maxCoeff() : 0.0; }
}  // namespace

TEST_F(CameraTest, SunPatchesAreSharpOnTheCarpetAndLightTheWall) {
  // Observer at (0, -3) facing +x; a sun beam 1 m x 1 m centred 2 m ahead doubles the light there.
  WorldState w = one_robot(Pose2(0.0, -3.0, 0.0));
  SunPatch beam;
  beam.centre = {2.0, -3.0};
  beam.half_size = {0.5, 0.5};
  beam.strength = 1.0;
  w.lighting.sun.push_back(beam);
  Rng rng(1);
  const CameraSettings half{9.0, 18.0};  // carpet green ~90 DN under the lamps, ~180 DN in the beam
  const Image im = cam_->render(w, 0, half, rng);
  const double inside = rgb_at(*cam_, im, {2.0, 0.0, 0.0})[1];
  EXPECT_NEAR(inside, 2.0 * PanoramicCamera::response(0.34, 1.0, half), 4.0);
  // The far edge x = 2.5 m: 8 cm either side (~3 px) it is fully in or out of the beam.
  EXPECT_NEAR(rgb_at(*cam_, im, {2.42, 0.0, 0.0})[1], inside, 4.0);
  EXPECT_NEAR(rgb_at(*cam_, im, {2.58, 0.0, 0.0})[1], PanoramicCamera::response(0.34, 1.0, half), 4.0);
  EXPECT_NEAR(rgb_at(*cam_, im, {0.5, -1.0, 0.0})[1], PanoramicCamera::response(0.34, 1.0, half), 4.0);  // elsewhere

  // Sun on the wall: observer at the centre facing +y, the wall's inner face at y = 7 m (1 m beyond
  // the touch line), lit 3x between x = -1 and 1 m, 0.1-0.4 m up.
  WorldState v = one_robot(Pose2(0.0, 0.0, kPi / 2));
  const Image dark = cam_->render(v, 0, half, rng);
  SunPatch window;
  window.surface = SunPatch::Surface::kWall;
  window.centre = {0.0, 7.0};
  window.half_size = {1.0, 0.0};
  window.z_min = 0.1;
  window.z_max = 0.4;
  window.strength = 2.0;
  v.lighting.sun.push_back(window);
  const Image lit = cam_->render(v, 0, half, rng);
  const Eigen::Vector3d in_patch(6.99, 0.0, 0.25), beside(6.99, -2.0, 0.25);  // robot frame: ahead = +y world
  EXPECT_NEAR(rgb_at(*cam_, lit, in_patch)[2] / rgb_at(*cam_, dark, in_patch)[2], 3.0, 0.3);
  EXPECT_NEAR(rgb_at(*cam_, lit, beside)[2], rgb_at(*cam_, dark, beside)[2], 2.0);
}

TEST_F(CameraTest, LightChangesBrightnessAndSaturationNotHue) {
  // The camera's white balance leaves the light white: a brighter scene is a brighter, and once a
  // channel clips a paler, carpet of the same hue.
  WorldState w = one_robot(Pose2(0.0, -3.0, 0.0));
  const CameraSettings half{9.0, 18.0};
  Rng rng(1);
  std::vector<Eigen::Vector3d> carpet;
  for (double level : {0.5, 1.0, 1.5, 4.0}) {
    w.lighting.level = level;
    carpet.push_back(rgb_at(*cam_, cam_->render(w, 0, half, rng), {1.0, 0.5, 0.0}));
  }
  // The albedo's hue is 125 degrees. Tolerance: the dim red and blue channels (~26 and ~31 DN at 1x)
  // carry the 8-bit GL quantisation (+-1-2 DN, a few degrees of hue); when green clips at 4x the hue
  // moves by 3-4 degrees towards cyan (a per-channel clip, as on a real sensor).
  for (const auto& c : carpet) EXPECT_NEAR(hue_deg(c), 125.0, 6.0) << c.transpose();
  EXPECT_LT(carpet[0][1], carpet[1][1]);
  EXPECT_LT(carpet[1][1], carpet[2][1]);
  EXPECT_NEAR(saturation(carpet[0]), saturation(carpet[1]), 0.1);  // no channel clips: the same saturation
  EXPECT_EQ(carpet[3][1], 255.0);                                   // 4x: green clips ...
  EXPECT_LT(saturation(carpet[3]), saturation(carpet[1]) - 0.08);   // ... and the carpet pales
}

TEST(CameraConfig, BadInputIsNamed) {
  auto path_of = [](const char* s) {
    try {
      CameraConfig::from_json(Json::parse(s), "/camera");
    } catch (const ConfigError& e) {
      return e.path();
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(path_of(R"({"mirror": "parabolic"})"), "/camera/mirror");
  EXPECT_EQ(path_of(R"({"width": 0})"), "/camera/width");
  EXPECT_EQ(path_of(R"({"height": -640})"), "/camera/height");
  EXPECT_EQ(path_of(R"({"exposure": 0})"), "/camera/exposure");
  EXPECT_EQ(path_of(R"({"exposure": -3})"), "/camera/exposure");
  EXPECT_EQ(path_of(R"({"backend": "vulkan"})"), "/camera/backend");
  EXPECT_EQ(path_of(R"({"mirror": "hyperbolic", "quality": "high"})"), "(accepted)");
  try {
    make_gl_context("directx");
    FAIL();
  } catch (const RuntimeFailure& e) {
    EXPECT_NE(std::string(e.what()).find("directx"), std::string::npos);
  }
}

TEST(CameraBackends, EglSurfacelessRendersTheSameScene) {
  CameraConfig c = quiet_camera();
  c.backend = "egl";
  std::unique_ptr<PanoramicCamera> egl;
  try {
    egl = std::make_unique<PanoramicCamera>(c, Field::preset("msl2012"));
  } catch (const RuntimeFailure& e) {
    GTEST_SKIP() << "EGL surfaceless unavailable here: " << e.what();
  }
  PanoramicCamera osm(quiet_camera(), Field::preset("msl2012"));
  const WorldState w = one_robot(Pose2(2.0, 1.0, -0.5));
  const Image a = egl->render_labels(w, 0), b = osm.render_labels(w, 0);
  std::size_t diff = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) diff += a.rgb[i] != b.rgb[i];
  EXPECT_LT(diff, a.rgb.size() / 1000);
}
