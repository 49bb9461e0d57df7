#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <utility>

#include "core/angles.hpp"
#include "core/fast_trig.hpp"
#include "core/field.hpp"
#include "core/json_reader.hpp"
#include "core/pose2.hpp"
#include "core/rng.hpp"

using namespace omniloc;

TEST(Angles, WrapIntoHalfOpenInterval) {
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(0.5), 0.5, 1e-15);
  EXPECT_NEAR(angle_diff(0.1, 2 * kPi - 0.1), 0.2, 1e-12);
}

TEST(FastSincos, WithinFourUlpOfLongDoubleAndExactFallbackOutsideItsRange) {
  // Reference: long double sinl/cosl (64-bit mantissa), rounded error in units of the double's ulp.
  const auto ulps = [](double got, long double ref) {
    const double r = std::fabs(static_cast<double>(ref));
    return static_cast<double>(std::fabs(static_cast<long double>(got) - ref)) / (std::nextafter(r, 2.0 * r + 1.0) - r);
  };
  std::uint64_t state = 12345;
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const double u = static_cast<double>(state >> 11) * 0x1.0p-53;  // [0, 1)
    const double x = (i % 2 ? 40.0 : 1e5) * (2.0 * u - 1.0);
    double s = 0.0, c = 0.0;
    sincos_fast(x, s, c);
    worst = std::max({worst, ulps(s, std::sin(static_cast<long double>(x))), ulps(c, std::cos(static_cast<long double>(x)))});
  }
  EXPECT_LT(worst, 4.0);
  for (const double x : {0.0, kPi / 2, kPi, -kPi, 1e5, -1e5}) {
    double s = 0.0, c = 0.0;
    sincos_fast(x, s, c);
    EXPECT_NEAR(s, std::sin(x), 1e-15) << x;
    EXPECT_NEAR(c, std::cos(x), 1e-15) << x;
  }
  for (const double x : {1e6, -3e7, 1e300}) {  // std::sin/cos beyond 1e5
    double s = 0.0, c = 0.0;
    sincos_fast(x, s, c);
    EXPECT_EQ(s, std::sin(x));
    EXPECT_EQ(c, std::cos(x));
  }
  double s = 0.0, c = 0.0;
  sincos_fast(std::numeric_limits<double>::quiet_NaN(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

TEST(FastAtan2, WithinFourUlpOfLongDoubleAndLibmAtTheSpecialCases) {
  std::uint64_t state = 6789;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53 * 2.0 - 1.0;  // [-1, 1)
  };
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = 50.0 * uniform();
    const double y = i % 4 == 0 ? x * (1.0 + 1e-9 * uniform()) : 50.0 * uniform();  // also near the diagonals
    const long double ref = std::atan2(static_cast<long double>(y), static_cast<long double>(x));
    const double r = std::fabs(static_cast<double>(ref));
    worst = std::max(worst, static_cast<double>(std::fabs(static_cast<long double>(atan2_fast(y, x)) - ref)) /
                                (std::nextafter(r, 2.0 * r + 1.0) - r));
  }
  EXPECT_LT(worst, 4.0);
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [y, x] : std::initializer_list<std::pair<double, double>>{
           {0.0, 1.0}, {-0.0, -1.0}, {0.0, -1.0}, {1.0, 0.0}, {-1.0, 0.0}, {1.0, 1.0}, {-1.0, -1.0}, {inf, 1.0}, {1.0, -inf}})
    EXPECT_EQ(atan2_fast(y, x), std::atan2(y, x)) << y << " " << x;
  EXPECT_TRUE(std::isnan(atan2_fast(std::numeric_limits<double>::quiet_NaN(), 1.0)));
}

TEST(Pose2, ComposeInverseBetween) {
  const Pose2 a(1.0, 2.0, 0.5), b(-0.3, 0.7, -2.0);
  const Pose2 ab = a.compose(b);
  const Pose2 back = a.between(ab);
  EXPECT_NEAR(back.x, b.x, 1e-12);
  EXPECT_NEAR(back.y, b.y, 1e-12);
  EXPECT_NEAR(back.theta, b.theta, 1e-12);
  const Pose2 id = a.compose(a.inverse());
  EXPECT_NEAR(id.x, 0, 1e-12);
  EXPECT_NEAR(id.y, 0, 1e-12);
  EXPECT_NEAR(id.theta, 0, 1e-12);
  const Eigen::Vector2d p(3, -1);
  EXPECT_TRUE(a.inverse_transform(a.transform(p)).isApprox(p, 1e-12));
  // Robot at (1,2) facing +y sees a world point at (1,3) straight ahead.
  const Pose2 r(1, 2, kPi / 2);
  EXPECT_TRUE(r.inverse_transform({1, 3}).isApprox(Eigen::Vector2d(1, 0), 1e-12));
}

TEST(Rng, StreamsAreReproducibleAndIndependent) {
  Rng a = Rng::stream(42, "odometry"), b = Rng::stream(42, "odometry"), c = Rng::stream(42, "compass");
  for (int i = 0; i < 100; ++i) {
    const double x = a.normal();
    EXPECT_EQ(x, b.normal());
  }
  EXPECT_NE(Rng::stream(42, "odometry").next_u64(), c.next_u64());
  Rng n(7);
  double s = 0, s2 = 0;
  const int N = 200000;
  for (int i = 0; i < N; ++i) {
    const double x = n.normal();
    s += x;
    s2 += x * x;
  }
  EXPECT_NEAR(s / N, 0.0, 0.01);
  EXPECT_NEAR(s2 / N, 1.0, 0.01);
}

class FieldTest : public ::testing::Test {
 protected:
  Field f = Field::preset("msl2012");
};

TEST_F(FieldTest, PresetDimensions) {
  EXPECT_EQ(f.length, 18.0);
  EXPECT_EQ(f.width, 12.0);
  EXPECT_EQ(f.line_width, 0.125);
  ASSERT_EQ(f.goals.size(), 2u);
  EXPECT_DOUBLE_EQ(f.goals[1].goal_line_x, 9.0);
  // 4 boundary + centre line + 2 x (3 penalty + 3 goal area) = 17 segments; circle + 4 corners.
  EXPECT_EQ(f.segments.size(), 17u);
  EXPECT_EQ(f.arcs.size(), 5u);
  EXPECT_EQ(f.spots.size(), 3u);
}

TEST_F(FieldTest, DistanceOnALine) {
  EXPECT_NEAR(f.distance_to_marking({4.5, -6.0}), 0.0, 1e-12);   // on the touch line
  EXPECT_NEAR(f.distance_to_marking({4.5, -5.7}), 0.3, 1e-12);   // 0.3 m inside the touch line
  EXPECT_NEAR(f.distance_to_marking({4.5, -6.8}), 0.8, 1e-12);   // outside the field
  EXPECT_TRUE(f.on_marking({4.5, -6.06}));
  EXPECT_FALSE(f.on_marking({4.5, -6.07}));
}

TEST_F(FieldTest, DistanceInsideCentreCircle) {
  // At (0.5, 1.0): centre line at 0.5, circle at 2 - sqrt(1.25) = 0.8820..., spot rim at sqrt(1.25)-0.075.
  EXPECT_NEAR(f.distance_to_marking({0.5, 1.0}), 0.5, 1e-12);
  // At (1.5, 0.3): circle 2 - sqrt(2.34) = 0.47028..., centre line 1.5.
  EXPECT_NEAR(f.distance_to_marking({1.5, 0.3}), 2.0 - std::sqrt(2.34), 1e-12);
  // Centre spot: inside the disc counts as on the marking.
  EXPECT_NEAR(f.distance_to_marking({0.05, 0.0}), 0.0, 1e-12);
}

TEST_F(FieldTest, DistanceAtCornerArc) {
  // Corner (9, 6); arc r = 0.75 about it on the field side. Point (8.6, 5.6): distance to corner
  // sqrt(0.32) = 0.5657, so 0.75 - 0.5657 to the arc; the lines are 0.4 away.
  EXPECT_NEAR(f.distance_to_marking({8.6, 5.6}), 0.75 - std::sqrt(0.32), 1e-12);
  // Outside the field beyond the corner the arc does not exist; the nearest is the corner itself.
  EXPECT_NEAR(f.distance_to_marking({9.3, 6.4}), 0.5, 1e-12);
  ArcMarking quarter{{0, 0}, 1.0, 0.0, kPi / 2};
  EXPECT_NEAR(distance_to_arc({-1, -1}, quarter), std::sqrt(4.0 + 1.0) - 0.0 * 1, 1e-12);  // nearest endpoint (1,0) or (0,1)
}

TEST(FieldJson, RejectsMisspeltKeyAndRange) {
  Json j = Json::parse(R"({"type": "msl", "lenght": 18})");
  try {
    Field::from_json(j, "/field");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/field/lenght");
  }
  j = Json::parse(R"({"type": "msl", "length": 30})");
  try {
    Field::from_json(j, "/field");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.path(), "/field/length");
    EXPECT_EQ(e.value(), "30");
  }
  EXPECT_THROW(Field::preset("nope"), ConfigError);
  Field big = Field::from_json(Json::parse(R"({"length": 22, "width": 14})"), "/field");
  EXPECT_NEAR(big.distance_to_marking({11, 0}), 0.0, 1e-12);
}
