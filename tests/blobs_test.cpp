// Blob detection on rendered panoramas (paper 003's cube arena, paper 004's coloured goals) and the
// landmark localizer on the detected blobs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <tuple>

#include "core/angles.hpp"
#include "core/field.hpp"
#include "harness/vision_setup.hpp"
#include "localization/landmarks/landmark_localizer.hpp"
#include "localization/vision/blobs.hpp"
#include "sim/occlusion.hpp"
#include "sim/render/panoramic_camera.hpp"
#include "testing/scenes.hpp"

using namespace omniloc;
using namespace omniloc::sim;

namespace {

using scenes::quiet_camera;

using scenes::one_robot;

double bearing_to(const Pose2& robot, const Eigen::Vector2d& target) {
  const Eigen::Vector2d d = target - robot.translation();
  return wrap_angle(std::atan2(d.y(), d.x()) - robot.theta);
}

// Distance from the robot centre to the nearest point of an axis-aligned square (a cube's footprint).
double distance_to_square(const Eigen::Vector2d& p, const Eigen::Vector2d& c, double half) {
  const double dx = std::max(0.0, std::fabs(p.x() - c.x()) - half), dy = std::max(0.0, std::fabs(p.y() - c.y()) - half);
  return std::hypot(dx, dy);
}

std::vector<Blob> regions(const std::vector<Blob>& blobs) {
  std::vector<Blob> out;
  for (const auto& b : blobs)
    if (b.kind == Blob::Kind::kRegion) out.push_back(b);
  return out;
}

}  // namespace

class BlobsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    arena_ = new Field(Field::preset("arena_10x8"));
    cam_ = new PanoramicCamera(quiet_camera(), *arena_);
    map_ = new CalibrationMap(harness::calibrate_camera(quiet_camera(), 1).map);
    table_ = new ColourTable(harness::colour_calibrate(quiet_camera(), *arena_, 1, 8));
  }
  static void TearDownTestSuite() {
    delete table_;
    delete map_;
    delete cam_;
    delete arena_;
  }
  static Field* arena_;
  static PanoramicCamera* cam_;
  static CalibrationMap* map_;
  static ColourTable* table_;
  // A pose from which all four cubes are seen, none in line with another.
  static inline const Pose2 kPose{1.0, 0.5, 0.4};
};
Field* BlobsTest::arena_ = nullptr;
PanoramicCamera* BlobsTest::cam_ = nullptr;
CalibrationMap* BlobsTest::map_ = nullptr;
ColourTable* BlobsTest::table_ = nullptr;

TEST_F(BlobsTest, ArenaFieldHasTheFourCubesOfPaper003) {
  ASSERT_EQ(arena_->landmarks.size(), 4u);
  int red = 0, blue = 0, yellow = 0;
  for (const auto& l : arena_->landmarks) {
    red += l.colour == "red";
    blue += l.colour == "blue";
    yellow += l.colour == "yellow";
  }
  EXPECT_EQ(red, 2);
  EXPECT_EQ(blue, 1);
  EXPECT_EQ(yellow, 1);
  EXPECT_DOUBLE_EQ(arena_->length, 10.0);
  EXPECT_DOUBLE_EQ(arena_->width, 8.0);
  EXPECT_TRUE(arena_->has_coloured_objects());
  EXPECT_FALSE(Field::preset("msl2012").has_coloured_objects());
  // Fields without coloured objects keep their fingerprint (the committed caches are named by it).
  EXPECT_EQ(Field::preset("msl2012").fingerprint(), "2a43db978ea6658f");
  EXPECT_NE(arena_->fingerprint(), Field::preset("msl2012").fingerprint());
  const Field msl2007 = Field::preset("msl2007");
  ASSERT_EQ(msl2007.goals.size(), 2u);
  EXPECT_TRUE(msl2007.has_coloured_objects());
  EXPECT_NE(msl2007.goals[0].colour, msl2007.goals[1].colour);
}

TEST_F(BlobsTest, OneBlobPerCubeWithBearingAndDistance) {
  Rng rng(1);
  const Image img = cam_->render(one_robot(kPose), 0, {}, rng);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  const std::vector<Blob> blobs = det.detect(img);
  const std::vector<Blob> reg = regions(blobs);
  EXPECT_EQ(reg.size(), blobs.size()) << "no edge observations without goal colours";
  // One region per cube of each colour.
  for (const ColourClass c : {kRed, kBlue, kYellow}) {
    const auto n_blobs = std::count_if(reg.begin(), reg.end(), [&](const Blob& b) { return b.colour == c; });
    const auto n_cubes = std::count_if(arena_->landmarks.begin(), arena_->landmarks.end(),
                                       [&](const Landmark& l) { return landmark_colour_class(l.colour) == c; });
    EXPECT_EQ(n_blobs, n_cubes) << colour_class_name(c);
  }
  double worst_deg = 0, worst_rel = 0;
  for (const auto& l : arena_->landmarks) {
    const double truth = bearing_to(kPose, l.position);
    const Blob* best = nullptr;
    for (const auto& b : reg)
      if (b.colour == landmark_colour_class(l.colour) && (!best || std::fabs(angle_diff(b.bearing, truth)) < std::fabs(angle_diff(best->bearing, truth))))
        best = &b;
    ASSERT_NE(best, nullptr) << l.id;
    EXPECT_LT(std::fabs(rad2deg(angle_diff(best->bearing, truth))), 1.0) << l.id;
    const double d_truth = distance_to_square(kPose.translation(), l.position, 0.5 * l.size);
    ASSERT_TRUE(best->has_distance) << l.id << " at " << d_truth << " m";
    EXPECT_LT(std::fabs(best->distance - d_truth) / d_truth, 0.10) << l.id << ": " << best->distance << " m against " << d_truth;
    EXPECT_GT(best->area_px, 25);
    EXPECT_FALSE(best->left_occluded || best->right_occluded) << l.id;
    worst_deg = std::max(worst_deg, std::fabs(rad2deg(angle_diff(best->bearing, truth))));
    worst_rel = std::max(worst_rel, std::fabs(best->distance - d_truth) / d_truth);
  }
  std::printf("cubes: worst bearing error %.3f deg, worst distance error %.1f %%\n", worst_deg, 100 * worst_rel);
}

TEST_F(BlobsTest, NoisyCameraStillFindsTheCubes) {
  // The default camera: vibration and pixel noise.
  const CameraConfig noisy;
  PanoramicCamera cam(noisy, *arena_);
  Rng rng(7);
  const Image img = cam.render(one_robot(kPose), 0, noisy.initial, rng);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  const std::vector<Blob> reg = regions(det.detect(img));
  ASSERT_EQ(reg.size(), 4u);
  for (const auto& l : arena_->landmarks) {
    const double truth = bearing_to(kPose, l.position);
    double err = 1e9;
    for (const auto& b : reg)
      if (b.colour == landmark_colour_class(l.colour)) err = std::min(err, std::fabs(angle_diff(b.bearing, truth)));
    EXPECT_LT(rad2deg(err), 1.5) << l.id;
  }
}

TEST_F(BlobsTest, CoveredImageGivesNoBlobs) {
  Image black;
  black.width = map_->image_width();
  black.height = map_->image_height();
  black.rgb.assign(static_cast<std::size_t>(black.width) * black.height * 3, 0);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  EXPECT_TRUE(det.detect(black).empty());
  // An image of the wrong size is not read.
  Image small;
  small.width = small.height = 10;
  small.rgb.assign(300, 200);
  EXPECT_TRUE(det.detect(small).empty());
}

TEST_F(BlobsTest, LocalizerRecoversThePoseFromTheFrame) {
  Rng rng(1);
  const Image img = cam_->render(one_robot(kPose), 0, {}, rng);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  Observations obs;
  obs.blobs = det.detect(img);
  LandmarkLocalizer loc(*arena_, LandmarkLocalizerParams{});
  loc.reset(std::nullopt);
  const Estimate e = loc.update(obs, Odometry{}, std::nullopt);
  ASSERT_TRUE(e.valid) << no_fix_reason_name(loc.last_frame().reason) << ": " << loc.last_frame().detail;
  EXPECT_EQ(e.mode, LocalizerMode::kFix);
  EXPECT_LT((e.pose.translation() - kPose.translation()).norm(), 0.2);
  EXPECT_LT(std::fabs(angle_diff(e.pose.theta, kPose.theta)), 0.05);
  EXPECT_EQ(e.extra.at("landmarks_used"), 4.0);
  EXPECT_EQ(e.extra.at("no_fix_reason"), 0.0);
  // The two red cubes were told apart: R1 is the one at +x.
  const auto& ids = loc.last_frame().ids;
  EXPECT_EQ(std::count(ids.begin(), ids.end(), "R1"), 1);
  EXPECT_EQ(std::count(ids.begin(), ids.end(), "R2"), 1);
}

TEST_F(BlobsTest, FewerThanThreeLandmarksGiveNoFixWithAReason) {
  Rng rng(1);
  Image img = cam_->render(one_robot(kPose), 0, {}, rng);
  // Black sectors (e.g. robots close by) over two of the cubes.
  std::vector<Sector> sectors;
  for (const auto& l : arena_->landmarks)
    if (l.id == "R1" || l.id == "B") sectors.push_back({bearing_to(kPose, l.position) - deg2rad(10), deg2rad(20)});
  paint_sectors(img, cam_->centre(), sectors);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  Observations obs;
  obs.blobs = det.detect(img);
  EXPECT_EQ(regions(obs.blobs).size(), 2u);
  LandmarkLocalizer loc(*arena_, LandmarkLocalizerParams{});
  loc.reset(std::nullopt);
  const Estimate e = loc.update(obs, Odometry{}, std::nullopt);
  EXPECT_FALSE(e.valid);
  EXPECT_EQ(e.mode, LocalizerMode::kNoFix);
  EXPECT_EQ(e.extra.at("no_fix_reason"), static_cast<double>(NoFixReason::kTooFewLandmarks));
  EXPECT_EQ(e.extra.at("no_fix_total"), 1.0);
  EXPECT_FALSE(loc.last_frame().detail.empty());
  EXPECT_TRUE(std::isfinite(e.pose.x) && std::isfinite(e.pose.y) && std::isfinite(e.pose.theta));
  // A covered camera is a no-fix frame too.
  obs.camera_ok = false;
  const Estimate e2 = loc.update(obs, Odometry{}, std::nullopt);
  EXPECT_FALSE(e2.valid);
  EXPECT_EQ(e2.extra.at("no_fix_reason"), static_cast<double>(NoFixReason::kCameraNotOk));
  EXPECT_EQ(e2.extra.at("no_fix_total"), 2.0);
}

TEST_F(BlobsTest, TwoRedCubesAreToldApartWithThreeBearings) {
  Rng rng(1);
  Image img = cam_->render(one_robot(kPose), 0, {}, rng);
  std::vector<Sector> sectors;
  for (const auto& l : arena_->landmarks)
    if (l.id == "B") sectors.push_back({bearing_to(kPose, l.position) - deg2rad(10), deg2rad(20)});
  paint_sectors(img, cam_->centre(), sectors);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  const std::vector<Blob> blobs = det.detect(img);
  ASSERT_EQ(regions(blobs).size(), 3u);
  // Bearings alone, no prediction: both red assignments are solved; in this arena the swapped one
  // puts the robot off the floor, so the right one wins.
  LandmarkLocalizerParams bearings_only;
  bearings_only.distance_sigma = 0;
  const LandmarkFrame f = LandmarkLocalizer(*arena_, bearings_only).solve(blobs, std::nullopt);
  ASSERT_EQ(f.reason, NoFixReason::kNone) << f.detail;
  EXPECT_EQ(f.assignments, 2);
  EXPECT_EQ(f.matched, 3);
  EXPECT_LT((f.fix.pose.translation() - kPose.translation()).norm(), 0.2);
  EXPECT_LT(std::fabs(angle_diff(f.fix.pose.theta, kPose.theta)), 0.05);
  // With distances too.
  const LandmarkFrame d = LandmarkLocalizer(*arena_, LandmarkLocalizerParams{}).solve(blobs, std::nullopt);
  ASSERT_EQ(d.reason, NoFixReason::kNone) << d.detail;
  EXPECT_LT((d.fix.pose.translation() - kPose.translation()).norm(), 0.2);
}

// Three red posts: any assignment fits three bearings exactly somewhere (resection), so without
// distances or a prediction the localizer must say it cannot tell. Synthetic blobs (exact bearings
// and distances).
TEST(LandmarkLocalizerTest, SameColouredLandmarksAreAmbiguousWithoutDistancesOrPrediction) {
  Json j = {{"type", "plain"}, {"length", 12.0}, {"width", 10.0}, {"landmarks", Json::array()}};
  const double angles[3] = {0.3, 2.0, 4.0}, radii[3] = {3.0, 2.5, 3.5};
  for (int k = 0; k < 3; ++k)
    j["landmarks"].push_back({{"id", "P" + std::to_string(k)}, {"colour", "red"}, {"shape", "post"}, {"size", 0.2},
                              {"position", {radii[k] * std::cos(angles[k]), radii[k] * std::sin(angles[k])}}});
  const Field field = Field::from_json(j, "/field");
  const Pose2 truth(0.4, -0.3, 1.0);
  std::vector<Blob> blobs;
  for (const auto& l : field.landmarks) {
    Blob b;
    b.colour = kRed;
    b.bearing = bearing_to(truth, l.position);
    b.distance = (l.position - truth.translation()).norm() - 0.1;
    b.has_distance = true;
    b.area_px = 100;
    blobs.push_back(b);
  }
  LandmarkLocalizerParams bearings_only;
  bearings_only.distance_sigma = 0;
  const LandmarkFrame amb = LandmarkLocalizer(field, bearings_only).solve(blobs, std::nullopt);
  EXPECT_EQ(amb.reason, NoFixReason::kAmbiguous) << amb.detail;
  EXPECT_EQ(amb.assignments, 6);
  const LandmarkFrame pred = LandmarkLocalizer(field, bearings_only).solve(blobs, Pose2(0.6, -0.1, 0.9));
  ASSERT_EQ(pred.reason, NoFixReason::kNone) << pred.detail;
  EXPECT_LT((pred.fix.pose.translation() - truth.translation()).norm(), 1e-6);
  // The distances tell them apart (in a symmetric layout, e.g. an equilateral triangle seen from
  // its centre, they could not).
  const LandmarkFrame dist = LandmarkLocalizer(field, LandmarkLocalizerParams{}).solve(blobs, std::nullopt);
  ASSERT_EQ(dist.reason, NoFixReason::kNone) << dist.detail;
  EXPECT_LT((dist.fix.pose.translation() - truth.translation()).norm(), 1e-6);
  EXPECT_LT(std::fabs(angle_diff(dist.fix.pose.theta, truth.theta)), 1e-6);
}

TEST_F(BlobsTest, DetectionTimePerFrame) {
  Rng rng(1);
  const Image img = cam_->render(one_robot(kPose), 0, {}, rng);
  const BlobDetector det(BlobParams{}, *map_, *table_);
  std::size_t n = 0;
  const int reps = 20;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < reps; ++i) n += det.detect(img).size();
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / reps;
  EXPECT_EQ(n, 4u * reps);
  RecordProperty("blob_detect_ms", std::to_string(ms));
  std::printf("blob detection: %.3f ms per 640 x 640 frame (mean of %d)\n", ms, reps);
}

// Paper 004's setting: goal edges on the legacy field.
TEST(BlobsGoalTest, GoalEdgesAndPoseOnTheLegacyField) {
  const Field field = Field::preset("msl2007");
  PanoramicCamera cam(quiet_camera(), field);
  const CalibrationMap map = harness::calibrate_camera(quiet_camera(), 1).map;
  const ColourTable table = harness::colour_calibrate(quiet_camera(), field, 1, 8);
  BlobParams bp;
  bp.edge_colours = {kYellow, kBlue};
  const BlobDetector det(bp, map, table);
  const std::vector<KnownObject> objects = known_objects(field);
  ASSERT_EQ(objects.size(), 4u);
  LandmarkLocalizer loc(field, LandmarkLocalizerParams{});
  // Paper 004's five positions in our frame (see scenarios/paper/landmarks_004.json).
  const std::vector<Pose2> poses = {{0.0, 1.15, 0.0}, {1.6, 0.0, 0.5}, {2.25, -1.0, -0.3}, {-1.6, 0.0, 2.0}, {-1.1, -1.17, 1.0}};
  for (const Pose2& pose : poses) {
    Rng rng(3);
    Observations obs;
    obs.blobs = det.detect(cam.render(one_robot(pose), 0, {}, rng));
    int edges = 0;
    for (const auto& b : obs.blobs) {
      if (b.kind == Blob::Kind::kRegion) continue;
      ++edges;
      // The edge's truth: the silhouette corner of that goal seen from the true position.
      const KnownObject* o = nullptr;
      for (const auto& k : objects)
        if (k.colour == b.colour && k.kind == b.kind) o = &k;
      ASSERT_NE(o, nullptr);
      const double truth = bearing_to(pose, o->seen_from(pose.translation()));
      EXPECT_LT(std::fabs(rad2deg(angle_diff(b.bearing, truth))), 1.0) << o->id << " from " << pose.x << ", " << pose.y;
    }
    EXPECT_EQ(edges, 4) << pose.x << ", " << pose.y;
    loc.reset(std::nullopt);
    const Estimate e = loc.update(obs, Odometry{}, std::nullopt);
    ASSERT_TRUE(e.valid) << no_fix_reason_name(loc.last_frame().reason) << " " << loc.last_frame().detail;
    EXPECT_LT((e.pose.translation() - pose.translation()).norm(), 0.2) << pose.x << ", " << pose.y;
    EXPECT_LT(std::fabs(angle_diff(e.pose.theta, pose.theta)), 0.05);
  }
}

// Between fixes: odometry moves the last pose; reported only when asked for, and only for
// max_prediction_time seconds.
TEST(LandmarkLocalizerTest, OdometryPredictionBetweenFixes) {
  const Field field = Field::preset("arena_10x8");
  const Pose2 truth(-1.0, 1.5, -0.7);
  std::vector<Blob> blobs;
  for (const auto& l : field.landmarks) {
    Blob b;
    b.colour = landmark_colour_class(l.colour);
    b.bearing = bearing_to(truth, l.position);
    b.area_px = 200;
    blobs.push_back(b);
  }
  LandmarkLocalizerParams p;
  p.odometry_prediction = true;
  p.max_prediction_time = 0.25;
  LandmarkLocalizer loc(field, p);
  loc.reset(std::nullopt);
  Observations obs;
  obs.blobs = blobs;
  const Estimate fix = loc.update(obs, Odometry{}, std::nullopt);
  ASSERT_TRUE(fix.valid);
  EXPECT_LT((fix.pose.translation() - truth.translation()).norm(), 1e-6);
  Odometry odo;
  odo.delta = Pose2(0.1, 0.0, 0.0);
  obs.blobs.clear();
  for (int k = 1; k <= 3; ++k) {
    obs.t = 0.1 * k;
    const Estimate e = loc.update(obs, odo, std::nullopt);
    const Pose2 expect = truth.compose(Pose2(0.1 * k, 0.0, 0.0));
    EXPECT_LT((e.pose.translation() - expect.translation()).norm(), 1e-6) << k;
    EXPECT_EQ(e.extra.at("no_fix_reason"), static_cast<double>(NoFixReason::kTooFewLandmarks));
    if (k <= 2) {
      EXPECT_TRUE(e.valid) << k;
      EXPECT_EQ(e.mode, LocalizerMode::kOdometry);
    } else {
      EXPECT_FALSE(e.valid) << "0.3 s after the fix, beyond max_prediction_time";
      EXPECT_EQ(e.mode, LocalizerMode::kNoFix);
    }
  }
}

namespace {

// Bit-for-bit equality of two detections (ties in the detector's sort key broken by the other fields).
void expect_same_blobs(std::vector<Blob> a, std::vector<Blob> b, const std::string& what) {
  auto key = [](const Blob& x) { return std::make_tuple(x.colour, x.kind, x.bearing, x.area_px, x.distance, x.left_bearing); };
  auto by_key = [&](const Blob& x, const Blob& y) { return key(x) < key(y); };
  std::sort(a.begin(), a.end(), by_key);
  std::sort(b.begin(), b.end(), by_key);
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].colour, b[k].colour) << what << ", blob " << k;
    EXPECT_EQ(a[k].kind, b[k].kind) << what << ", blob " << k;
    EXPECT_EQ(a[k].bearing, b[k].bearing) << what << ", blob " << k;
    EXPECT_EQ(a[k].left_bearing, b[k].left_bearing) << what << ", blob " << k;
    EXPECT_EQ(a[k].right_bearing, b[k].right_bearing) << what << ", blob " << k;
    EXPECT_EQ(a[k].distance, b[k].distance) << what << ", blob " << k;
    EXPECT_EQ(a[k].has_distance, b[k].has_distance) << what << ", blob " << k;
    EXPECT_EQ(a[k].area_px, b[k].area_px) << what << ", blob " << k;
    EXPECT_EQ(a[k].left_occluded, b[k].left_occluded) << what << ", blob " << k;
    EXPECT_EQ(a[k].right_occluded, b[k].right_occluded) << what << ", blob " << k;
  }
}

}  // namespace

// detect() classifies a grid and flood-fills from it; detect_full() classifies every pixel and runs
// OpenCV's connected components. Same blobs to the bit on rendered frames: quiet and noisy camera,
// black sectors cutting cubes (occluded edges), edge observations, several minimum areas.
TEST_F(BlobsTest, GridSearchGivesTheFullResolutionBlobs) {
  PanoramicCamera noisy(CameraConfig{}, *arena_);
  // The sectors are painted (0, 0, 0); the table learnt the robots' black, a little brighter.
  std::uint8_t dark = 0;
  for (int g = 0; g < 100 && !dark; ++g) {
    const std::uint8_t rgb[3] = {static_cast<std::uint8_t>(g), static_cast<std::uint8_t>(g), static_cast<std::uint8_t>(g)};
    if (table_->classify(rgb) == kObstacleBlack) dark = rgb[0];
  }
  ASSERT_GT(dark, 0);
  Rng rng(21), poses(5);
  int blobs = 0, occluded = 0;
  for (int k = 0; k < 10; ++k) {
    const Pose2 pose(poses.uniform(-4.5, 4.5), poses.uniform(-3.5, 3.5), poses.uniform(-3.1, 3.1));
    Image img = (k % 2 ? noisy : *cam_).render(one_robot(pose), 0, {}, rng);
    if (k % 3 == 0) {  // a black sector over one side of each cube
      std::vector<Sector> sectors;
      for (const auto& l : arena_->landmarks) sectors.push_back({bearing_to(pose, l.position), deg2rad(4)});
      paint_sectors(img, cam_->centre(), sectors);
      for (std::size_t i = 0; i < img.rgb.size(); i += 3)
        if (img.rgb[i] == 0 && img.rgb[i + 1] == 0 && img.rgb[i + 2] == 0) img.rgb[i] = img.rgb[i + 1] = img.rgb[i + 2] = dark;
    }
    for (const int min_area : {1, 8, 25, 100}) {
      BlobParams p;
      p.min_area_px = min_area;
      p.edge_colours = {kRed, kBlue};
      const BlobDetector det(p, *map_, *table_);
      ASSERT_LT((det.grid_rows() - 1) * (det.grid_cols() - 1), min_area);
      const std::vector<Blob> fast = det.detect(img);
      expect_same_blobs(fast, det.detect_full(img), "frame " + std::to_string(k) + ", min_area_px " + std::to_string(min_area));
      blobs += static_cast<int>(fast.size());
      for (const Blob& b : fast) occluded += b.left_occluded + b.right_occluded;
    }
  }
  EXPECT_GT(blobs, 100);
  EXPECT_GT(occluded, 0);  // the occlusion test ran on lazily classified pixels
}

// The grid's guarantee on regions it could only just catch: 1-pixel-wide lines between grid rows or
// columns, a diagonal line (8-connected only), and a region that fills a whole grid cell, hence
// below min_area_px, which neither path reports. Then random thin scribbles, touching black
// patches, at several minimum areas.
TEST_F(BlobsTest, GridSearchFindsThinRegions) {
  const std::array<std::uint8_t, 3> green{60, 140, 60}, red{220, 40, 40}, blue{40, 60, 200}, black{10, 10, 10};
  ColourTable table(6);
  {
    Image im, lab;
    im.width = lab.width = 8;
    im.height = lab.height = 1;
    const std::pair<std::array<std::uint8_t, 3>, ColourClass> learnt[] = {{green, kFieldGreen}, {red, kRed}, {blue, kBlue}, {black, kObstacleBlack}};
    for (const auto& [rgb, cls] : learnt)
      for (int rep = 0; rep < 2; ++rep) {
        im.rgb.insert(im.rgb.end(), rgb.begin(), rgb.end());
        lab.rgb.insert(lab.rgb.end(), {static_cast<std::uint8_t>(cls), 0, 0});
      }
    table.learn({im}, {lab});
  }
  const int w = map_->image_width(), h = map_->image_height();
  const int cu = static_cast<int>(map_->centre().x()), cv = static_cast<int>(map_->centre().y());
  ASSERT_LT(map_->min_radius(), 120.0);
  auto blank = [&] {
    Image img;
    img.width = w;
    img.height = h;
    img.rgb.resize(static_cast<std::size_t>(w) * h * 3);
    for (std::size_t i = 0; i < img.rgb.size(); i += 3) std::copy(green.begin(), green.end(), img.rgb.begin() + static_cast<std::ptrdiff_t>(i));
    return img;
  };
  auto paint = [&](Image& img, int u, int v, const std::array<std::uint8_t, 3>& rgb) {
    if (u >= 0 && v >= 0 && u < w && v < h) std::copy(rgb.begin(), rgb.end(), img.row(v) + 3 * u);
  };

  const BlobDetector det(BlobParams{}, *map_, table);
  const int gr = det.grid_rows(), gc = det.grid_cols();
  ASSERT_LT((gr - 1) * (gc - 1), BlobParams{}.min_area_px);
  Image img = blank();
  // Grid rows are v % gr == 0, grid columns u % gc == 0: lines one past them.
  const int vh = (cv - 150) / gr * gr + 1, uv = (cu + 150) / gc * gc + 1;
  for (int k = 0; k < 30; ++k) paint(img, cu - 15 + k, vh, red);   // horizontal, between grid rows
  for (int k = 0; k < 30; ++k) paint(img, uv, cv - 15 + k, blue);  // vertical, between grid columns
  for (int k = 0; k < 30; ++k) paint(img, cu - 200 + k, cv + 40 + k, red);  // diagonal
  const int cell_u = (cu - 150) / gc * gc + 1, cell_v = (cv + 150) / gr * gr + 1;
  for (int dv = 0; dv < gr - 1; ++dv)
    for (int du = 0; du < gc - 1; ++du) paint(img, cell_u + du, cell_v + dv, blue);  // a whole cell
  const std::vector<Blob> found = det.detect(img);
  ASSERT_EQ(found.size(), 3u);
  for (const Blob& b : found) EXPECT_EQ(b.area_px, 30);
  expect_same_blobs(found, det.detect_full(img), "lines");

  Rng rng(99);
  const std::array<std::uint8_t, 3>* colours[] = {&red, &blue, &black};
  for (int k = 0; k < 8; ++k) {
    img = blank();
    for (int s = 0; s < 60; ++s) {
      const double r = rng.uniform(130.0, 300.0), a = rng.uniform(-kPi, kPi);
      int u = cu + static_cast<int>(r * std::cos(a)), v = cv + static_cast<int>(r * std::sin(a));
      const auto& rgb = *colours[rng.uniform_index(3)];
      const int len = 1 + static_cast<int>(rng.uniform_index(60));
      for (int step = 0; step < len; ++step) {
        paint(img, u, v, rgb);
        u += static_cast<int>(rng.uniform_index(3)) - 1;
        v += static_cast<int>(rng.uniform_index(3)) - 1;
      }
    }
    for (const int min_area : {1, 3, 10, 25, 50}) {
      BlobParams p;
      p.min_area_px = min_area;
      p.edge_colours = {kRed};
      const BlobDetector d(p, *map_, table);
      expect_same_blobs(d.detect(img), d.detect_full(img), "scribbles " + std::to_string(k) + ", min_area_px " + std::to_string(min_area));
    }
  }
}
