#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "core/field.hpp"
#include "core/rng.hpp"
#include "harness/vision_setup.hpp"
#include "localization/vision/scan_lines.hpp"
#include "sim/occlusion.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {
using scenes::quiet_camera;
}  // namespace

class VisionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    field_ = new Field(Field::preset("msl2012"));
    cam_ = new PanoramicCamera(quiet_camera(), *field_);
    map_ = new CalibrationMap(harness::calibrate_camera(quiet_camera(), 1).map);
    table_ = new ColourTable(harness::colour_calibrate(quiet_camera(), *field_, 1, 8));
  }
  static void TearDownTestSuite() {
    delete table_;
    delete map_;
    delete cam_;
    delete field_;
  }
  static WorldState world(const Pose2& p) { return scenes::one_robot(p); }
  static Field* field_;
  static PanoramicCamera* cam_;
  static CalibrationMap* map_;
  static ColourTable* table_;
};
Field* VisionTest::field_ = nullptr;
PanoramicCamera* VisionTest::cam_ = nullptr;
CalibrationMap* VisionTest::map_ = nullptr;
ColourTable* VisionTest::table_ = nullptr;

TEST_F(VisionTest, CalibrationMapMatchesTheTrueMirror) {
  for (double d : {1.0, 4.0})
    for (int k = 0; k < 24; ++k) {
      const double b = kTwoPi * k / 24 + 0.05;
      const Eigen::Vector2d truth(d * std::cos(b), d * std::sin(b));
      const auto px = cam_->project({truth.x(), truth.y(), 0.0});
      ASSERT_TRUE(px);
      const auto back = map_->to_robot(px->x(), px->y());
      ASSERT_TRUE(back);
      // Paper-002-style requirement: 2 cm at 1 m, 5 cm at 4 m (plus the half pixel of the table).
      EXPECT_LT((*back - truth).norm(), d < 2 ? 0.03 : 0.05) << "d " << d << " bearing " << b;
    }
}

TEST_F(VisionTest, ScanLinesFindRenderedLinesWithin2Px) {
  const Pose2 pose(-4.0, -1.0, 0.3);
  Rng rng(1);
  const Image img = cam_->render(world(pose), 0, {}, rng);
  const LineDetector det(ScanLineParams{}, *map_, *table_);
  const ScanResult r = det.detect(img);
  ASSERT_GT(r.points.size(), 40u);
  int checked = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const auto fp = cam_->floor_point(r.pixels[i].x(), r.pixels[i].y());
    ASSERT_TRUE(fp);
    const double range = fp->norm();
    if (range > 6.0) continue;
    // Metres per pixel along the ray there (truth), to express the miss in pixels.
    const Eigen::Vector2d dir = (r.pixels[i] - cam_->centre()).normalized();
    const auto fp2 = cam_->floor_point(r.pixels[i].x() + dir.x(), r.pixels[i].y() + dir.y());
    ASSERT_TRUE(fp2);
    const double m_per_px = (*fp2 - *fp).norm();
    const double miss_px = std::max(0.0, field_->distance_to_marking(pose.transform(*fp)) - 0.5 * field_->line_width) / m_per_px;
    EXPECT_LT(miss_px, 2.0) << "point " << i << " at " << range << " m";
    // And through the calibration map, on the true line within a few centimetres.
    EXPECT_LT(field_->distance_to_marking(pose.transform(r.points[i])), 0.08) << "robot-frame point " << i;
    ++checked;
  }
  EXPECT_GT(checked, 30);
}

TEST_F(VisionTest, ObstaclesAndBlackSectorsGiveNoPoints) {
  const Pose2 pose(-1.0, -2.0, 0.0);  // the centre line x = 0 lies 1 m ahead
  WorldState w = world(pose);
  Rng rng(2);
  Image img = cam_->render(w, 0, {}, rng);
  const LineDetector det(ScanLineParams{}, *map_, *table_);
  auto ahead = [&](const ScanResult& r) {
    int n = 0;
    for (const auto& p : r.points) n += std::fabs(std::atan2(p.y(), p.x())) < deg2rad(15) && p.x() < 3.0;
    return n;
  };
  ASSERT_GT(ahead(det.detect(img)), 0);
  RobotState other;
  other.id = 1;
  other.pose = Pose2(-0.4, -2.0, 0.0);
  w.robots.push_back(other);
  img = cam_->render(w, 0, {}, rng);
  EXPECT_EQ(ahead(det.detect(img)), 0) << "a robot in front hides the line";
  w.robots.pop_back();
  img = cam_->render(w, 0, {}, rng);
  paint_sectors(img, cam_->centre(), {{deg2rad(-30), deg2rad(60)}});
  EXPECT_EQ(ahead(det.detect(img)), 0) << "a black sector gives no points";
  // A covered camera: no observation at all.
  std::fill(img.rgb.begin(), img.rgb.end(), std::uint8_t{0});
  const Observations o = det.observe(img, 0.0);
  EXPECT_FALSE(o.camera_ok);
  EXPECT_TRUE(o.line_points.empty());
}

TEST_F(VisionTest, TablesAndMapsOfAnotherFieldOrSizeAreRefused) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string t = (dir / "omniloc_table.lut").string(), m = (dir / "omniloc_map.json").string();
  table_->save(t);
  EXPECT_NO_THROW(ColourTable::load(t, field_->fingerprint()));
  EXPECT_THROW(ColourTable::load(t, "another-field"), ConfigError);
  map_->save(m);
  EXPECT_NO_THROW(CalibrationMap::load(m, "", 640, 640));
  EXPECT_THROW(CalibrationMap::load(m, "", 800, 800), ConfigError);
  EXPECT_THROW(CalibrationMap::load((dir / "omniloc_missing_map.json").string()), ConfigError);
  EXPECT_THROW(ColourTable::load((dir / "omniloc_missing.lut").string()), ConfigError);
}

// The calibration estimates the mirror axis from the rim, so a decentred mirror (NuBot's
// calibration files correct about 9 px) is calibrated instead of becoming map error. The renderer's
// centre() is the truth, used here only.
TEST(CalibrationCentre, RimFitGivesTheMirrorAxisWithin1PxAndTheMapKeepsItsBounds) {
  const Field field = Field::preset("msl2012");
  for (const Eigen::Vector2d& offset : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(9.0, 0.0), Eigen::Vector2d(6.4, -6.4), Eigen::Vector2d(-5.2, 7.4)}) {
    CameraConfig cfg;  // default noise: read and shot noise (calibration turns vibration off)
    cfg.centre_offset_px = offset;
    const PanoramicCamera cam(cfg, field);
    const CalibrationResult r = harness::calibrate_camera(cfg, 1);
    EXPECT_LT((r.map.centre() - cam.centre()).norm(), 1.0) << "offset " << offset.transpose() << ": estimated " << r.map.centre().transpose();
    EXPECT_NEAR(r.rim.radius, cam.rim_px(), 1.0);
    EXPECT_GT(r.rim.edge_points, 400);
    // The bounds of CalibrationMapMatchesTheTrueMirror, for every bearing.
    for (double d : {1.0, 4.0})
      for (int k = 0; k < 24; ++k) {
        const double b = kTwoPi * k / 24 + 0.05;
        const Eigen::Vector2d truth(d * std::cos(b), d * std::sin(b));
        const auto px = cam.project({truth.x(), truth.y(), 0.0});
        ASSERT_TRUE(px);
        const auto back = r.map.to_robot(px->x(), px->y());
        ASSERT_TRUE(back) << "offset " << offset.transpose() << " d " << d << " bearing " << b;
        EXPECT_LT((*back - truth).norm(), d < 2 ? 0.03 : 0.05) << "offset " << offset.transpose() << " d " << d << " bearing " << b;
      }
  }
}

TEST(CalibrationCentre, ImageCentreAssumptionFailsTheBoundsWithADecentredMirror) {
  // What the calibration did before: with the mirror 9 px off the image centre the map misses by
  // decimetres somewhere at 4 m (this is what the rim fit removes; it also shows the test above can fail).
  CameraConfig cfg;
  cfg.centre_offset_px = {9.0, 0.0};
  const PanoramicCamera cam(cfg, Field::preset("msl2012"));
  const CalibrationResult r = harness::calibrate_camera(cfg, 1, nullptr, harness::CentreSource::kImageCentre);
  EXPECT_EQ(r.map.centre(), Eigen::Vector2d(320.0, 320.0));
  double worst = 0;
  for (int k = 0; k < 24; ++k) {
    const double b = kTwoPi * k / 24 + 0.05;
    const Eigen::Vector2d truth(4.0 * std::cos(b), 4.0 * std::sin(b));
    const auto px = cam.project({truth.x(), truth.y(), 0.0});
    const auto back = px ? r.map.to_robot(px->x(), px->y()) : std::nullopt;
    if (back) worst = std::max(worst, (*back - truth).norm());
  }
  EXPECT_GT(worst, 0.05);
}

TEST(CalibrationCentre, CircleFitIsExactAndDropsOutliers) {
  std::vector<Eigen::Vector2d> pts;
  const Eigen::Vector2d c(331.7, 308.2);
  Rng rng(5);
  for (int k = 0; k < 300; ++k) {
    const double a = 0.2 + 4.5 * k / 300.0;  // a partial arc (the rim clipped by the image border)
    pts.push_back(c + (313.6 + rng.normal(0.0, 0.2)) * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  for (int k = 0; k < 30; ++k) pts.push_back(c + rng.uniform(150.0, 300.0) * Eigen::Vector2d(std::cos(0.1 * k), std::sin(0.1 * k)));
  std::vector<bool> inlier;
  const MirrorRim rim = fit_circle(pts, &inlier);
  EXPECT_LT((rim.centre - c).norm(), 0.05);
  EXPECT_NEAR(rim.radius, 313.6, 0.05);
  EXPECT_EQ(rim.edge_points, 300);
  EXPECT_EQ(rim.rejected, 30);
  EXPECT_LT(rim.rms_px, 0.25);
}

TEST(CalibrationCentre, Version1MapsStillLoad) {
  // Maps written before the centre was estimated: version 1, no rim; the centre they stored is used.
  const auto file = (std::filesystem::temp_directory_path() / "omniloc_map_v1.json").string();
  {
    std::ofstream out(file);
    out << R"({"format":"omniloc-calibration-map","version":1,"width":640,"height":640,"centre":[320.0,320.0],"tag":"t",)"
        << R"("radii_px":[[40,60,80,100],[40,60,80,100],[40,60,80,100],[40,60,80,100]],)"
        << R"("distances_m":[[0.5,1,1.5,2],[0.5,1,1.5,2],[0.5,1,1.5,2],[0.5,1,1.5,2]]})";
  }
  const CalibrationMap m = CalibrationMap::load(file, "t", 640, 640);
  EXPECT_EQ(m.centre(), Eigen::Vector2d(320.0, 320.0));
  EXPECT_EQ(m.rim_radius, 0.0);
  const auto d = m.ground_distance(60.0, 0.3);
  ASSERT_TRUE(d);
  EXPECT_NEAR(*d, 1.0, 1e-9);
  // Saved again it is version 2 and reads back the same.
  m.save(file);
  const CalibrationMap m2 = CalibrationMap::load(file, "t", 640, 640);
  EXPECT_EQ(m2.centre(), m.centre());
  EXPECT_NEAR(*m2.ground_distance(60.0, 0.3), 1.0, 1e-9);
}

// The error budget's "calibration map" row (the model-free map measured from
// rendered images) tracked better than the baseline's exact map (the simulator's own mirror). This
// measures line points of rendered frames at known poses, splitting each point's radial error into the
// detector's part (where the pixel it reports truly looks, against the line's centre along the ray)
// and each map's part (where the map puts that pixel, against where it truly looks). It found the
// detector's half-pixel offset (-1.25 cm; now -0.26 cm), which the exact map passed on unchanged.
namespace {
struct RadialSplit {
  double detector_cm = 0, exact_map_cm = 0, free_map_cm = 0, exact_total_abs_cm = 0, free_total_abs_cm = 0;
  int n = 0, additive = 0;
};

/// Signed radial offset (metres, + outward) from a robot-frame floor point to the nearest line centre
/// along its ray, found by a search of +-15 cm in 1 mm steps (the field's markings are 12.5 cm wide).
std::optional<double> to_line_centre(const Field& f, const Pose2& pose, const Eigen::Vector2d& p) {
  const Eigen::Vector2d dir = p.normalized();
  double best = 1e9, at = 0;
  for (int k = -150; k <= 150; ++k) {
    const double d = f.distance_to_marking(pose.transform(p + dir * (k * 0.001)));
    if (d < best) best = d, at = k * 0.001;
  }
  if (best > 0.01) return std::nullopt;  // no line centre crossed along the ray nearby (a corner, a circle's tangent)
  return -at;                            // the point lies `-at` beyond the centre
}
}  // namespace

TEST_F(VisionTest, LinePointRadialErrorSplitsIntoDetectorAndMap) {
  const CalibrationMap exact = harness::exact_calibration(quiet_camera());
  // One detector gives the pixels; each map then turns the same pixels into metres.
  const LineDetector det_free(ScanLineParams{}, *map_, *table_);
  RadialSplit s;
  Rng rng(7);
  for (const Pose2& pose : {Pose2(-4.0, -1.0, 0.3), Pose2(1.5, 2.0, -1.1), Pose2(3.0, -2.5, 2.4), Pose2(-1.0, 0.7, 0.0)}) {
    const Image img = cam_->render(world(pose), 0, {}, rng);
    const ScanResult rf = det_free.detect(img);
    for (std::size_t i = 0; i < rf.pixels.size(); ++i) {
      const auto truth = cam_->floor_point(rf.pixels[i].x(), rf.pixels[i].y());
      const auto pe = exact.to_robot(rf.pixels[i].x(), rf.pixels[i].y());
      ASSERT_TRUE(truth && pe);
      if (truth->norm() > 6.0) continue;
      const auto det_off = to_line_centre(*field_, pose, *truth);
      const auto ef = to_line_centre(*field_, pose, rf.points[i]);
      const auto ee = to_line_centre(*field_, pose, *pe);
      if (!det_off || !ef || !ee) continue;
      s.detector_cm += 100 * *det_off;
      s.exact_map_cm += 100 * (pe->norm() - truth->norm());
      s.free_map_cm += 100 * (rf.points[i].norm() - truth->norm());
      s.exact_total_abs_cm += 100 * std::abs(*ee);
      // The split adds up where both searches find the same crossing (not near a corner or where a
      // circle runs along the ray): the exact map's point lies beyond the line centre by the
      // detector's offset plus the map's own radial error.
      if (std::abs(*ee - (*det_off + (pe->norm() - truth->norm()))) < 0.01) ++s.additive;
      s.free_total_abs_cm += 100 * std::abs(*ef);
      ++s.n;
    }
  }
  ASSERT_GT(s.n, 150);
  const double n = s.n;
  EXPECT_GT(s.additive, 0.8 * s.n);
  std::printf("line points %d (split adds up for %d): detector radial offset %+.2f cm; map error exact %+.2f cm, model-free %+.2f cm; "
              "|total| exact %.2f cm, model-free %.2f cm\n",
              s.n, s.additive, s.detector_cm / n, s.exact_map_cm / n, s.free_map_cm / n, s.exact_total_abs_cm / n, s.free_total_abs_cm / n);
  // The exact map is the true mirror (up to its 5 cm tabulation and the pixel-centre lookup): its
  // mean radial error stays small. The detector reports the middle of the white run: its mean radial
  // offset is well under the half pixel (about 1.2 cm here) that taking the last white pixel's near
  // edge as the run's end put on every point before commit 6184583 (measured -1.25 cm, now -0.26 cm).
  // (The model-free figures are the detector's own points, taken on the floor rather than at the
  // pixel: NearLinePointsAreCentredOnTheFloor.)
  EXPECT_LT(std::abs(s.exact_map_cm / n), 1.0);
  EXPECT_LT(std::abs(s.detector_cm / n), 0.6);
}

// Within 1 m the default mirror's radius-distance law is curved (an exponential inner part), so
// the middle of a white run in image radius is not the middle of the line on the floor: for a
// square crossing at floor distance D of a line of width w it lies -D'' w^2 / (8 D'^2) short,
// 1.3 cm at 0.45 m (docs/modern_localizer.md "The bias's cause"). The detector takes the middle
// of the run's two edges on the floor instead, along the ray's own bearing (not the calibration
// table's value at the pixel holding the middle, up to half a pixel off across and along the ray).
// Through the simulator's exact mirror, so that only the detector is measured. Before (middle in
// image radius, pixel's table value): -1.36 cm within 0.9 m, mean |offset| 1.70 cm at 0.9-6 m;
// -0.37 cm and 1.26 cm with the middle on the floor (53b1f48); -0.17 cm and 0.99 cm since the
// renderer draws each pixel's own floor point (a4652a0: CameraTest.FloorLinesLieWhereTheMirrorPutsThem).
TEST_F(VisionTest, NearLinePointsAreCentredOnTheFloor) {
  const CalibrationMap exact = harness::exact_calibration(quiet_camera());
  const LineDetector det(ScanLineParams{}, exact, *table_);
  double near_sum = 0, far_abs = 0;
  int near_n = 0, far_n = 0;
  Rng rng(11);
  // Robots 0.4-0.8 m from the halfway line, a touch line, a goal line and the centre circle.
  for (const Pose2& pose : {Pose2(-0.5, 3.0, 0.2), Pose2(0.6, -3.5, 1.0), Pose2(2.0, 5.4, 0.4), Pose2(-3.0, -5.3, 2.0),
                            Pose2(8.4, 2.5, -0.7), Pose2(1.4, 0.3, 2.9), Pose2(-0.4, 1.6, -2.2), Pose2(-5.0, 2.0, 0.0)}) {
    const Image img = cam_->render(world(pose), 0, {}, rng);
    const ScanResult r = det.detect(img);
    for (const Eigen::Vector2d& p : r.points) {
      const auto off = to_line_centre(*field_, pose, p);
      if (!off) continue;
      if (p.norm() < 0.9) {
        near_sum += 100 * *off;
        ++near_n;
      } else if (p.norm() < 6.0) {
        far_abs += 100 * std::abs(*off);
        ++far_n;
      }
    }
  }
  ASSERT_GT(near_n, 60);
  ASSERT_GT(far_n, 300);
  std::printf("within 0.9 m: %d points, mean offset along the ray %+.2f cm; 0.9-6 m: %d points, mean |offset| %.2f cm\n", near_n,
              near_sum / near_n, far_n, far_abs / far_n);
  EXPECT_LT(std::abs(near_sum / near_n), 0.6);
  EXPECT_LT(far_abs / far_n, 1.45);
}

// A white run shorter than a painted line could be where it lies is not a line. Isolated
// white specks on the carpet (the salt-and-pepper classification of a colour near the table's
// white/green boundary, e.g. inside a sun patch) gave a line point per speck.
TEST_F(VisionTest, WhiteSpecksNarrowerThanALineGiveNoPoints) {
  const Pose2 pose(-4.0, -1.0, 0.3);
  Rng rng(3);
  Image img = cam_->render(world(pose), 0, {}, rng);
  const LineDetector det(ScanLineParams{}, *map_, *table_);
  const std::size_t lines_only = det.detect(img).points.size();
  // A white pixel from a line, then one speck every 4 px in a ring of the image where the floor is
  // green (radius 70-110 px, near the robot, where a painted line is several pixels wide).
  std::array<std::uint8_t, 3> white{};
  for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3)
    if (table_->classify(&img.rgb[i]) == kLineWhite) {
      std::copy(&img.rgb[i], &img.rgb[i] + 3, white.begin());
      break;
    }
  int specks = 0;
  const Eigen::Vector2d c = cam_->centre();
  for (int v = 0; v < img.height; v += 4)
    for (int u = (v / 4) % 2 * 2; u < img.width; u += 4) {
      const double r = (Eigen::Vector2d(u + 0.5, v + 0.5) - c).norm();
      std::uint8_t* px = &img.rgb[3 * (static_cast<std::size_t>(v) * img.width + u)];
      if (r < 70 || r > 110 || table_->classify(px) != kFieldGreen) continue;
      std::copy(white.begin(), white.end(), px);
      ++specks;
    }
  ASSERT_GT(specks, 500);
  EXPECT_LE(det.detect(img).points.size(), lines_only + 3);  // the specks add (almost) nothing
  ScanLineParams old;
  old.min_width_factor = 0.0;  // the detector before commit 6184583: no lower bound on the run
  const LineDetector lax(old, *map_, *table_);
  EXPECT_GT(lax.detect(img).points.size(), lines_only + 20);
}
