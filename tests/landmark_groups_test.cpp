// Paper 003's landmark groups, matching and voting (localization/landmarks/landmark_groups.hpp), and
// the landmark_maps experiment in quick mode.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/angles.hpp"
#include "core/json_reader.hpp"
#include "core/rng.hpp"
#include "experiments/experiment.hpp"
#include "experiments/landmark_maps.hpp"
#include "localization/landmarks/landmark_groups.hpp"

using namespace omniloc;
using namespace omniloc::landmarks;

namespace {

struct WorldLandmark {
  Eigen::Vector2d p;
  int colour;
};

// Exact sightings of the landmarks from `robot`, listed in the order given by `order`.
std::vector<LandmarkSighting> sight(const std::vector<WorldLandmark>& lm, const Pose2& robot, const std::vector<std::size_t>& order) {
  std::vector<LandmarkSighting> s;
  for (std::size_t i : order) {
    const Eigen::Vector2d rel = robot.inverse_transform(lm[i].p);
    s.push_back({lm[i].colour, rel.norm(), std::atan2(rel.y(), rel.x())});
  }
  return s;
}

// Which world landmarks a group's members are (through the order used when sighting).
std::array<std::size_t, 3> world_members(const LandmarkGroup& g, const std::vector<std::size_t>& order) {
  return {order[g.member[0]], order[g.member[1]], order[g.member[2]]};
}

// Two red landmarks, one blue, one yellow on a square: two groups, mirror images (paper 003, fig. 1).
const std::vector<WorldLandmark> kSquare = {{{-4, -4}, 0}, {{-4, 4}, 1}, {{4, -4}, 2}, {{4, 4}, 0}};

}  // namespace

TEST(LandmarkGroups, FeatureInvariantToRobotPose) {
  const std::vector<WorldLandmark> lm = {{{3.0, 1.0}, 7}, {{-2.0, 4.5}, 2}, {{0.5, -3.0}, 5}};
  // Colours increasing: 2 (landmark 1), 5 (landmark 2), 7 (landmark 3).
  const GroupFeature ref = group_feature(lm[1].p, lm[2].p, lm[0].p);
  const std::vector<Pose2> poses = {Pose2(0, 0, 0), Pose2(3.2, -2.1, 1.1), Pose2(-5, 7, -2.5), Pose2(10, 10, kPi)};
  const std::vector<std::vector<std::size_t>> orders = {{0, 1, 2}, {2, 0, 1}, {1, 2, 0}, {2, 1, 0}};
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto s = sight(lm, poses[k], orders[k]);
    const auto groups = form_groups(s);
    ASSERT_EQ(groups.size(), 1u);
    EXPECT_EQ(groups[0].colour, (std::array<int, 3>{2, 5, 7}));
    EXPECT_NEAR(groups[0].feature.d12, ref.d12, 1e-12);
    EXPECT_NEAR(groups[0].feature.d13, ref.d13, 1e-12);
    EXPECT_NEAR(groups[0].feature.angle, ref.angle, 1e-12);
  }
  // The angle is signed: the mirror image of the group has the opposite angle, same distances.
  const GroupFeature mirror = group_feature({lm[1].p.x(), -lm[1].p.y()}, {lm[2].p.x(), -lm[2].p.y()}, {lm[0].p.x(), -lm[0].p.y()});
  EXPECT_NEAR(mirror.d12, ref.d12, 1e-12);
  EXPECT_NEAR(mirror.angle, -ref.angle, 1e-12);
  EXPECT_GT(std::fabs(ref.angle), 0.1);
}

TEST(LandmarkGroups, OnlyDifferentColoursFormGroups) {
  const auto s = sight(kSquare, Pose2(0.3, -0.2, 0.4), {0, 1, 2, 3});
  const auto groups = form_groups(s);
  ASSERT_EQ(groups.size(), 2u);  // (red 1, blue, yellow) and (red 2, blue, yellow); never two reds
  for (const auto& g : groups) EXPECT_EQ(g.colour, (std::array<int, 3>{0, 1, 2}));
  EXPECT_NEAR(std::fabs(groups[0].feature.angle), kPi / 2, 1e-12);
  EXPECT_NEAR(groups[0].feature.angle, -groups[1].feature.angle, 1e-12);
  // Bad sightings are skipped.
  auto bad = s;
  bad[1].distance = std::nan("");
  EXPECT_EQ(form_groups(bad).size(), 0u);  // the only blue one is gone
}

TEST(LandmarkGroups, IdenticalGroupsMatchAcrossFrames) {
  const std::vector<std::size_t> o1 = {0, 1, 2, 3}, o2 = {3, 2, 0, 1};
  const auto s1 = sight(kSquare, Pose2(0.5, 0.5, 0.0), o1);
  const auto s2 = sight(kSquare, Pose2(1.5, -0.7, 2.0), o2);
  const auto g1 = form_groups(s1), g2 = form_groups(s2);
  ASSERT_EQ(g1.size(), 2u);
  ASSERT_EQ(g2.size(), 2u);
  const GroupMatchParams p;
  const auto m = match_groups(g1, g2, p);
  ASSERT_EQ(m.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_GE(m[i], 0);
    // The same physical landmarks, in the same roles.
    EXPECT_EQ(world_members(g2[i], o2), world_members(g1[static_cast<std::size_t>(m[i])], o1));
  }
  EXPECT_NE(m[0], m[1]);

  // Within the thresholds still matched; beyond them, or with other colours, not.
  auto shifted = g2;
  shifted[0].feature.d12 += 0.4;
  shifted[1].feature.angle += deg2rad(9.0);
  const auto m2 = match_groups(g1, shifted, p);
  EXPECT_EQ(m2, m);
  shifted[0].feature.d13 += 0.6;
  const auto m3 = match_groups(g1, shifted, p);
  EXPECT_EQ(m3[0], -1);
  EXPECT_EQ(m3[1], m[1]);
  auto recoloured = g2;
  recoloured[1].colour = {0, 1, 3};
  EXPECT_EQ(match_groups(g1, recoloured, p)[1], -1);
  // One-to-one: two copies of one group compete for it; the closer one wins.
  std::vector<LandmarkGroup> twins = {g1[0], g1[0]};
  twins[0].feature.d12 += 0.3;
  twins[1].feature.d12 += 0.1;
  const auto m4 = match_groups(std::vector<LandmarkGroup>{g1[0]}, twins, p);
  EXPECT_EQ(m4, (std::vector<int>{-1, 0}));
}

TEST(LandmarkGroups, VotingRejectsAnOutlier) {
  // Three fixes within 0.2 m and 3 degrees of each other, one wrong fix far away, listed first.
  const std::vector<Pose2> fixes = {Pose2(5.0, -3.0, 0.1), Pose2(1.0, 1.0, 0.10), Pose2(1.1, 0.9, 0.12), Pose2(0.95, 1.1, 0.07)};
  FixVoter voter(Pose2(0, 0, 0));
  const VoteResult r = voter.vote(fixes, PlausibleRegion::everywhere());
  EXPECT_TRUE(r.accepted);
  EXPECT_FALSE(r.forced);
  EXPECT_EQ(r.votes, 3);
  EXPECT_EQ(r.fix_votes, (std::vector<int>{1, 3, 3, 3}));  // the outlier has only its own vote
  EXPECT_EQ(r.members, (std::vector<int>{1, 2, 3}));       // the average accepted last: the best-voted fix first
  EXPECT_NEAR(r.position.x, (1.0 + 1.1 + 0.95) / 3, 1e-12);
  EXPECT_NEAR(r.position.y, (1.0 + 0.9 + 1.1) / 3, 1e-12);
  EXPECT_NEAR(r.position.theta, 0.0966, 1e-3);
  EXPECT_EQ(r.deadlock, 0);

  // Near in position but 20 degrees off in heading: no vote.
  const std::vector<Pose2> turned = {Pose2(1.0, 1.0, 0.0), Pose2(1.05, 1.0, deg2rad(20.0))};
  EXPECT_EQ(FixVoter().vote(turned, PlausibleRegion::everywhere()).fix_votes, (std::vector<int>{1, 1}));
  // The paper's literal loop counts only later fixes.
  VotingParams lit;
  lit.later_only = true;
  EXPECT_EQ(FixVoter(Pose2(), lit).vote(std::vector<Pose2>(fixes.begin() + 1, fixes.end()), PlausibleRegion::everywhere()).fix_votes,
            (std::vector<int>{3, 2, 1}));
  // Heading averaged on the circle across +-pi.
  const std::vector<Pose2> wrap = {Pose2(0, 0, kPi - 0.02), Pose2(0, 0, -kPi + 0.02)};
  EXPECT_NEAR(std::fabs(FixVoter().vote(wrap, PlausibleRegion::everywhere()).position.theta), kPi, 1e-9);
}

TEST(LandmarkGroups, PlausibleRegion) {
  const auto r = PlausibleRegion::from_path({0, 0}, {4, 0});
  EXPECT_NEAR(r.centre.x(), 2.0, 1e-15);
  EXPECT_NEAR(r.radius, 2.0, 1e-15);
  EXPECT_TRUE(r.contains({2.0, 1.99}));
  EXPECT_TRUE(r.contains({0.0, 0.0}));
  EXPECT_FALSE(r.contains({2.0, 2.01}));
  EXPECT_FALSE(r.contains({-0.1, 0.0}));
  EXPECT_TRUE(PlausibleRegion::from_path({0, 0}, {4, 0}, 0.5).contains({-0.4, 0.0}));
  EXPECT_TRUE(PlausibleRegion::everywhere().contains({1e9, -1e9}));
}

TEST(LandmarkGroups, DeadlockAcceptsAfterMoreThanThreeFrames) {
  const auto region = PlausibleRegion::from_path({0, 0}, {4, 0});  // centre (2, 0), radius 2
  FixVoter v(Pose2(0, 0, 0));
  const std::vector<Pose2> outside = {Pose2(10, 10, 0)};
  for (int k = 1; k <= 4; ++k) {
    const VoteResult r = v.vote(outside, region);
    EXPECT_FALSE(r.accepted) << "frame " << k;
    EXPECT_TRUE(r.members.empty());
    EXPECT_EQ(r.deadlock, k);
    EXPECT_EQ(r.position.x, 0.0);  // the last position is kept
  }
  // Fifth frame: deadlock = 4 > 3, the position is accepted although implausible.
  VoteResult r = v.vote(outside, region);
  EXPECT_TRUE(r.accepted);
  EXPECT_TRUE(r.forced);
  EXPECT_EQ(r.position.x, 10.0);
  EXPECT_EQ(r.deadlock, 0);
  // A frame without fixes is a deadlock too; the position is kept.
  r = v.vote({}, region);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.deadlock, 1);
  EXPECT_EQ(r.position.x, 10.0);
  // A plausible fix is accepted at once and clears the deadlock.
  r = v.vote(std::vector<Pose2>{Pose2(1, 0.5, 0)}, region);
  EXPECT_TRUE(r.accepted);
  EXPECT_FALSE(r.forced);
  EXPECT_EQ(r.position.x, 1.0);
  EXPECT_EQ(r.deadlock, 0);
  // With deadlock_limit 0 a single bad frame is enough to force the next one.
  VotingParams p;
  p.deadlock_limit = 0;
  FixVoter w(Pose2(), p);
  EXPECT_FALSE(w.vote(outside, region).accepted);
  EXPECT_TRUE(w.vote(outside, region).forced);
}

TEST(LandmarkGroups, BestVotedOutsideRegionKeepsThePlausibleOne) {
  // The paper's order: a plausible single fix first, then a better-voted pair outside the region. The
  // pair raises maxvote but is not accepted, so the plausible fix stands (and vice versa in order).
  const auto region = PlausibleRegion::from_path({0, 0}, {4, 0});
  const std::vector<Pose2> a = {Pose2(1, 0, 0), Pose2(8, 8, 0), Pose2(8.1, 8, 0)};
  const std::vector<Pose2> b = {Pose2(8, 8, 0), Pose2(8.1, 8, 0), Pose2(1, 0, 0)};
  for (const auto* fixes : {&a, &b}) {
    FixVoter v;
    const VoteResult r = v.vote(*fixes, region);
    EXPECT_TRUE(r.accepted);
    EXPECT_EQ(r.votes, 1);
    EXPECT_EQ(r.position.x, 1.0);
    EXPECT_EQ(r.members, (std::vector<int>{fixes == &a ? 0 : 2}));
  }
}

TEST(LandmarkGroups, LocalizerNoiseFreeTracksTheRobot) {
  GroupLocalizer loc(Pose2(0, 0, 0));
  Pose2 truth(0, 0, 0);
  for (int k = 0; k < 30; ++k) {
    const auto s = sight(kSquare, truth, {static_cast<std::size_t>(k % 4), static_cast<std::size_t>((k + 1) % 4),
                                          static_cast<std::size_t>((k + 2) % 4), static_cast<std::size_t>((k + 3) % 4)});
    const auto r = loc.update(s, PlausibleRegion::everywhere());
    if (k == 0) {
      EXPECT_TRUE(r.fixes.empty());  // every group new: coordinates set, no fix yet
      EXPECT_EQ(r.groups.size(), 2u);
    } else {
      EXPECT_EQ(r.fixes.size(), 2u);
      EXPECT_TRUE(r.vote.accepted);
      EXPECT_EQ(r.vote.votes, 2);
      EXPECT_NEAR(r.estimate.x, truth.x, 1e-9);
      EXPECT_NEAR(r.estimate.y, truth.y, 1e-9);
      EXPECT_NEAR(angle_diff(r.estimate.theta, truth.theta), 0.0, 1e-9);
      for (const auto& g : r.groups) EXPECT_LT(g.id, 2);  // still the first two groups
    }
    truth = Pose2(truth.x + 0.1, truth.y + 0.05 * std::sin(0.3 * k), truth.theta + 0.1);
  }
}

TEST(LandmarkGroups, MemoryRecognisesAGroupAfterAGap) {
  // Frame 0: both groups seen; frame 1: the blue landmark hidden (no group); frame 2: seen again.
  for (const bool remember : {false, true}) {
    GroupLocalizerParams p;
    p.remember_groups = remember;
    GroupLocalizer loc(Pose2(0, 0, 0), p);
    loc.update(sight(kSquare, Pose2(0, 0, 0), {0, 1, 2, 3}), PlausibleRegion::everywhere());
    EXPECT_TRUE(loc.update(sight(kSquare, Pose2(0.1, 0, 0), {0, 2, 3}), PlausibleRegion::everywhere()).groups.empty());
    const Pose2 truth(0.2, 0.1, 0.3);
    const auto r = loc.update(sight(kSquare, truth, {3, 2, 1, 0}), PlausibleRegion::everywhere());
    ASSERT_EQ(r.groups.size(), 2u);
    for (const auto& g : r.groups) {
      if (remember) {
        EXPECT_LT(g.id, 2);  // the groups of frame 0, with their coordinates
        EXPECT_GE(g.previous, 0);
      } else {
        EXPECT_GE(g.id, 2);  // paper 003: only the previous frame counts, so they are new again
        EXPECT_EQ(g.previous, -1);
      }
    }
    if (remember) {
      ASSERT_EQ(r.fixes.size(), 2u);
      EXPECT_NEAR(r.estimate.x, truth.x, 1e-9);
      EXPECT_NEAR(r.estimate.y, truth.y, 1e-9);
    } else {
      EXPECT_TRUE(r.fixes.empty());
    }
  }
}

TEST(LandmarkMapsExperiment, QuickRunWritesItsFiles) {
  namespace fs = std::filesystem;
  const experiments::ExperimentInfo* info = nullptr;
  for (const auto& e : experiments::all())
    if (e.name == "landmark_maps") info = &e;
  ASSERT_NE(info, nullptr);
  const fs::path dir = fs::temp_directory_path() / ("omniloc_landmark_maps_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  experiments::ExperimentArgs args;
  args.seed = 3;
  args.quick = true;
  args.out_dir = dir.string();
  std::ostringstream out;
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(info->run(args, out), 0);
  // Recorded, not asserted: a wall-clock limit fails on a busy machine (speed lives in bench/).
  RecordProperty("quick_run_s", std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  for (const char* f : {"landmark_maps.json", "maps_004.csv", "table1_004.json", "table1_004.md", "sim_003.json",
                        "sim_003_paper_consecutive.png", "sim_003_paper_memory.png", "sim_003_distractor_consecutive.png",
                        "sim_003_distractor_memory.png", "map_two_circle_004.png", "map_three_point_004.png", "map_circle_intersection_003.png",
                        "map_total_like.png"})
    EXPECT_TRUE(fs::exists(dir / f) && fs::file_size(dir / f) > 0) << f;

  std::ifstream in(dir / "table1_004.json");
  const Json t = Json::parse(in);
  ASSERT_FALSE(t["tables"].empty());
  for (const auto& table : t["tables"]) {
    ASSERT_EQ(table["rows"].size(), 5u);
    for (const auto& row : table["rows"])
      for (const char* s : {"two_circle_004", "three_point_004"}) {
        const auto& c = row["ours"][s];
        for (const char* k : {"mean_x_cm", "mean_y_cm", "mean_err_cm"}) {
          ASSERT_TRUE(c[k].is_number()) << s << " " << k;
          EXPECT_TRUE(std::isfinite(c[k].get<double>())) << s << " " << k;
        }
        EXPECT_LT(c["mean_err_cm"].get<double>(), 100.0) << s;  // 0.5 and 2 degrees of noise on a 6 m field
      }
    EXPECT_TRUE(table["rows"][0].contains("published"));
  }
  std::ifstream sj(dir / "sim_003.json");
  const Json sim = Json::parse(sj);
  for (const char* c : {"paper_consecutive", "paper_memory", "distractor_consecutive", "distractor_memory"}) {
    const auto& a = sim[c]["all_paths"];
    EXPECT_GT(a["group_fixes"].get<int>(), 0) << c;
    EXPECT_TRUE(std::isfinite(a["voting_mean_m"].get<double>())) << c;
    EXPECT_TRUE(std::isfinite(a["fixes_max_m"].get<double>())) << c;
  }
  EXPECT_NE(out.str().find("table 1"), std::string::npos);

  // Paper 004 as printed (table1_004.json, /as_printed): the numbers that follow from the published table
  // alone are exact; the Monte Carlo ones (2000 trials in quick mode) within their sampling spread.
  const auto& ap = t["as_printed"];
  ASSERT_TRUE(ap["computed"].get<bool>());
  EXPECT_NEAR(ap["published_ratio"].get<double>(), (106.775 + 131.4) / 2 / ((38.601 + 19.647 + 11.045) / 3) /
                                                       ((18.385 + 38.275) / 2 / ((30.0 + 13.601 + 7.211) / 3)), 1e-12);
  for (const auto& row : ap["rows"]) EXPECT_TRUE(row["same_set"].get<bool>());
  EXPECT_NEAR(ap["rows"][2]["implied_two_circle"]["diff_deg"][1].get<double>(), 45.92, 0.01);   // (75, 100): theta2 off by 46 deg
  EXPECT_NEAR(ap["rows"][4]["implied_two_circle"]["diff_deg"][1].get<double>(), -53.94, 0.01);  // (410, 83)
  EXPECT_NEAR(ap["sigma"]["ml_deg"].get<double>(), 5.014, 0.001);
  const double s_match = ap["sigma"]["mean_match_deg"].get<double>();
  EXPECT_GT(s_match, 1.4);
  EXPECT_LT(s_match, 2.1);
  // Same bearings, same point: with independent draws per method the two-circle error is above the
  // three-point one at all five positions with probability 1/32 (0.031; 2000 trials: sd 0.004).
  for (const char* m : {"mean_match", "ml"}) {
    const auto& mc = ap["monte_carlo"][m];
    EXPECT_NEAR(mc["p_two_circle_worse_at_all_five"].get<double>(), 1.0 / 32, 0.015) << m;
    EXPECT_NEAR(mc["median_ratio"].get<double>(), 1.0, 0.15) << m;
  }
  EXPECT_EQ(ap["monte_carlo"]["mean_match"]["n_both_edges_ge_published_two_circle"].get<long>(), 0);

  // Paper 003's voting bound (sim_003.json, /paper_memory/voting_cause).
  const auto& vc = sim["paper_memory"]["voting_cause"];
  const auto& dist = vc["error_distribution"];
  EXPECT_EQ(dist["max_m"].get<double>(), sim["paper_memory"]["all_paths"]["voting_max_m"].get<double>());
  EXPECT_LE(dist["p50_m"].get<double>(), dist["p95_m"].get<double>());
  EXPECT_LE(dist["p95_m"].get<double>(), dist["p99_m"].get<double>());
  EXPECT_LE(dist["p99_m"].get<double>(), dist["max_m"].get<double>());
  EXPECT_EQ(dist["frames_over_1m"].get<long>(),
            dist["over_1m_accepted"].get<long>() + dist["over_1m_kept_with_fixes"].get<long>() + dist["over_1m_kept_without_fix"].get<long>());
  EXPECT_EQ(dist["frames"].get<long>(), sim["paper_memory"]["all_paths"]["frames"].get<long>());
  for (const char* w : {"worst", "worst_accepted"}) {
    const auto& f = vc[w];
    ASSERT_TRUE(f.is_object()) << w;
    // estimate - truth = (estimate - truth at the source) + (truth at the source - truth now)
    EXPECT_LE(f["err_m"].get<double>(), f["source_err_m"].get<double>() + f["stale_m"].get<double>() + 1e-12) << w;
    EXPECT_GE(f["err_m"].get<double>(), std::fabs(f["source_err_m"].get<double>() - f["stale_m"].get<double>()) - 1e-12) << w;
    if (f["accepted"].get<bool>()) {
      EXPECT_EQ(f["stale_m"].get<double>(), 0.0) << w;
    }
    EXPECT_GE(f["dilution_m_per_m"].get<double>(), 0.0) << w;
  }
  EXPECT_TRUE(vc["worst_accepted"]["accepted"].get<bool>());
  EXPECT_FALSE(sim["paper_consecutive"].contains("voting_cause"));
  // Paper 003's own real run (its table 1): waypoint 6, (-1000, 4000) mm measured at (447, 4412) mm.
  EXPECT_NEAR(sim["paper_real_run"]["max_error_m"].get<double>(), std::hypot(1447.0, 412.0) / 1000, 1e-12);
  EXPECT_EQ(sim["paper_real_run"]["max_at_waypoint"].get<int>(), 6);
  fs::remove_all(dir);
}

// Dilution of a group fix with respect to its landmarks' coordinates (landmark_maps.hpp, fix_dilution):
// two exact identities of bearing-only positioning.
TEST(LandmarkMapsExperiment, FixDilutionIdentities) {
  const std::array<Eigen::Vector2d, 3> lm = {Eigen::Vector2d(-4, -4), Eigen::Vector2d(-4, 4), Eigen::Vector2d(4, -4)};
  const Pose2 robot(0.7, -1.2, 0.4);
  std::array<double, 3> b{};
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d rel = robot.inverse_transform(lm[k]);
    b[k] = std::atan2(rel.y(), rel.x());
  }
  // Moving every landmark by the same vector moves the fix by that vector: with one common direction u,
  // J0 + J1 + J2 = u, so distance errors of +1 m each give exactly a 1 m fix error.
  const Eigen::Vector2d u = Eigen::Vector2d(0.6, 0.8);
  const auto same = experiments::fix_dilution(lm, b, {u, u, u});
  const Eigen::Vector2d sum = same.J[0] + same.J[1] + same.J[2];
  EXPECT_NEAR(sum.x(), u.x(), 1e-6);
  EXPECT_NEAR(sum.y(), u.y(), 1e-6);
  EXPECT_GE(same.worst, 1.0 - 1e-6);
  // Scaling the landmarks about the robot leaves every bearing from it unchanged, so the fix stays: along
  // the lines of sight from the robot, sum |L_k - robot| J_k = 0.
  std::array<Eigen::Vector2d, 3> dirs;
  for (std::size_t k = 0; k < 3; ++k) dirs[k] = (lm[k] - robot.translation()).normalized();
  const auto los = experiments::fix_dilution(lm, b, dirs);
  Eigen::Vector2d z = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < 3; ++k) z += (lm[k] - robot.translation()).norm() * los.J[k];
  EXPECT_NEAR(z.norm(), 0.0, 1e-6);
  EXPECT_TRUE(std::isfinite(los.worst));
}
