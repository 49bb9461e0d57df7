#include "localization/landmarks/landmark_localizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "core/angles.hpp"
#include "localization/landmarks/landmark_solvers.hpp"

namespace omniloc {

using landmarks::BearingObs;
using landmarks::Fix;

const ParamList<LandmarkLocalizerParams>& LandmarkLocalizerParams::params() {
  using P = LandmarkLocalizerParams;
  static const ParamList<P> list = {
      integer_param("min_landmarks", &P::min_landmarks, 3, 100, "fewer matched bearings: no fix (3 is the minimum for any solver)"),
      positive_param("bearing_sigma_deg", &P::bearing_sigma_deg, 45.0, "deg", "expected bearing noise: assignment cost and covariance"),
      positive_param("max_bearing_rms_deg", &P::max_bearing_rms_deg, 90.0, "deg", "a fix whose RMS bearing residual is larger is refused (>= 4 bearings)"),
      number_param("distance_sigma", &P::distance_sigma, 0.0, 10.0, "", "relative error of blob distances in the cost; 0: distances unused"),
      number_param("prediction_sigma", &P::prediction_sigma, 0.0, 100.0, "m", "predicted position's weight in the cost; 0: prediction unused"),
      positive_param("prediction_sigma_theta_deg", &P::prediction_sigma_theta_deg, 360.0, "deg", "predicted heading's weight in the cost"),
      number_param("ambiguity_margin", &P::ambiguity_margin, 0.0, 1e6, "chi-square", "closer rivals make the frame ambiguous"),
      number_param("floor_slack", &P::floor_slack, 0.0, 100.0, "m", "a fix may lie this far outside the floor (walls) before it is discarded"),
      bool_param("skip_occluded", &P::skip_occluded, "blobs whose edge may be cut by an occluder are not used"),
      bool_param("odometry_prediction", &P::odometry_prediction, "report the odometry-predicted pose on frames without a fix"),
      number_param("max_prediction_time", &P::max_prediction_time, 0.0, 1e6, "s", "after the last fix, prediction is used this long (cost and output)"),
      integer_param("max_assignments", &P::max_assignments, 1, 100000, "assignments tried per frame at most"),
  };
  return list;
}

LandmarkLocalizerParams LandmarkLocalizerParams::from_json(JsonReader& r) {
  LandmarkLocalizerParams p;
  read_params(r, p, params());
  return p;
}

const char* no_fix_reason_name(NoFixReason r) {
  switch (r) {
    case NoFixReason::kNone: return "fix";
    case NoFixReason::kCameraNotOk: return "camera not ok";
    case NoFixReason::kTooFewLandmarks: return "too few landmarks";
    case NoFixReason::kSolverRefused: return "solver refused";
    case NoFixReason::kInconsistent: return "inconsistent bearings";
    case NoFixReason::kAmbiguous: return "ambiguous assignment";
  }
  return "?";
}

Eigen::Vector2d KnownObject::seen_from(const Eigen::Vector2d& viewpoint) const {
  if (!is_goal_edge) return position;
  // Extreme corner of the footprint rectangle, measured from the direction to its centre.
  const Eigen::Vector2d centre = 0.5 * (footprint_min + footprint_max);
  const double ref = std::atan2(centre.y() - viewpoint.y(), centre.x() - viewpoint.x());
  const Eigen::Vector2d corners[4] = {footprint_min, {footprint_max.x(), footprint_min.y()}, footprint_max, {footprint_min.x(), footprint_max.y()}};
  Eigen::Vector2d best = position;
  double best_a = kind == Blob::Kind::kLeftEdge ? -kTwoPi : kTwoPi;
  for (const auto& c : corners) {
    const double a = angle_diff(std::atan2(c.y() - viewpoint.y(), c.x() - viewpoint.x()), ref);
    if (kind == Blob::Kind::kLeftEdge ? a > best_a : a < best_a) {
      best_a = a;
      best = c;
    }
  }
  return best;
}

std::vector<KnownObject> known_objects(const Field& field) {
  std::vector<KnownObject> out;
  for (const auto& l : field.landmarks) {
    KnownObject o;
    o.colour = landmark_colour_class(l.colour);
    if (o.colour == kUnknown) continue;
    o.id = l.id;
    o.kind = Blob::Kind::kRegion;
    o.position = l.position;
    o.half_size = 0.5 * l.size;
    out.push_back(o);
  }
  for (const auto& g : field.goals) {
    const ColourClass c = landmark_colour_class(g.colour);
    if (c == kUnknown) continue;
    // Footprint of posts and net, as rendered: posts centred on the goal line, net to g.depth behind.
    const double s = g.side(), yw = 0.5 * g.width + g.post_width;
    const double xa = g.goal_line_x - s * 0.5 * g.post_width, xb = g.goal_line_x + s * g.depth;
    for (const bool left : {true, false}) {
      KnownObject o;
      o.colour = c;
      o.kind = left ? Blob::Kind::kLeftEdge : Blob::Kind::kRightEdge;
      o.id = g.colour + (left ? "_goal_left" : "_goal_right");
      o.is_goal_edge = true;
      o.footprint_min = {std::min(xa, xb), -yw};
      o.footprint_max = {std::max(xa, xb), yw};
      // Front outer corner (what the robot sees from in front of the goal) as the nominal position.
      const Eigen::Vector2d post = left ? g.left_post() : g.right_post();
      o.position = {xa, post.y() > 0 ? yw : -yw};
      out.push_back(o);
    }
  }
  return out;
}

LandmarkLocalizer::LandmarkLocalizer(const Field& field, const LandmarkLocalizerParams& p)
    : field_(field), p_(p), objects_(known_objects(field)) {}

void LandmarkLocalizer::reset(const std::optional<Pose2>& start) {
  have_pose_ = start.has_value();
  pose_ = start.value_or(Pose2());
  since_fix_ = start ? 0.0 : 1e9;
  have_t_ = false;
  no_fix_total_ = 0;
  last_ = LandmarkFrame{};
}

namespace {

struct Candidate {
  Fix fix;
  double cost = 0.0;
  double rms = 0.0;
  std::vector<std::pair<int, int>> pairs;  // (blob, object)
};

// All sequences of distinct elements of [0, n) of length k.
void sequences(int n, int k, std::vector<int>& cur, std::vector<bool>& used, std::vector<std::vector<int>>& out) {
  if (static_cast<int>(cur.size()) == k) {
    out.push_back(cur);
    return;
  }
  for (int i = 0; i < n; ++i) {
    if (used[i]) continue;
    used[i] = true;
    cur.push_back(i);
    sequences(n, k, cur, used, out);
    cur.pop_back();
    used[i] = false;
  }
}

// Usable blobs and the objects they can be, grouped by (colour, kind): (blob indices, object indices).
using BlobGroups = std::map<std::pair<int, int>, std::pair<std::vector<int>, std::vector<int>>>;

BlobGroups group_blobs(const std::vector<Blob>& blobs, const std::vector<KnownObject>& objects, bool skip_occluded) {
  BlobGroups groups;
  for (int i = 0; i < static_cast<int>(blobs.size()); ++i) {
    const Blob& b = blobs[i];
    if (skip_occluded) {
      if (b.kind == Blob::Kind::kRegion && (b.left_occluded || b.right_occluded)) continue;
      if (b.kind == Blob::Kind::kLeftEdge && b.left_occluded) continue;
      if (b.kind == Blob::Kind::kRightEdge && b.right_occluded) continue;
    }
    const std::pair<int, int> key{b.colour, static_cast<int>(b.kind)};
    groups[key].first.push_back(i);
  }
  for (int j = 0; j < static_cast<int>(objects.size()); ++j) {
    const std::pair<int, int> key{objects[j].colour, static_cast<int>(objects[j].kind)};
    auto it = groups.find(key);
    if (it != groups.end()) it->second.second.push_back(j);
  }
  return groups;
}

// One group's candidate pairings, each a list of (blob, object).
using GroupOptions = std::vector<std::vector<std::pair<int, int>>>;

// Per group: every one-to-one pairing of min(#blobs, #objects) blobs and objects. At most two
// surplus blobs per group are considered (the largest). `matched`: the bearings one assignment
// (one pairing per group) holds.
std::vector<GroupOptions> pairings(BlobGroups& groups, const std::vector<Blob>& blobs, int& matched) {
  std::vector<GroupOptions> options;
  matched = 0;
  for (auto& [key, g] : groups) {
    auto& [bl, ob] = g;
    if (ob.empty()) continue;
    std::stable_sort(bl.begin(), bl.end(), [&](int a, int b) { return blobs[a].area_px > blobs[b].area_px; });
    if (bl.size() > ob.size() + 2) bl.resize(ob.size() + 2);
    const bool blobs_fewer = bl.size() <= ob.size();
    const int k = static_cast<int>(std::min(bl.size(), ob.size()));
    const int n = static_cast<int>(std::max(bl.size(), ob.size()));
    std::vector<std::vector<int>> seqs;
    std::vector<int> cur;
    std::vector<bool> used(static_cast<std::size_t>(n), false);
    sequences(n, k, cur, used, seqs);
    GroupOptions opts;
    for (const auto& s : seqs) {
      std::vector<std::pair<int, int>> pairs;
      for (int i = 0; i < k; ++i)
        pairs.emplace_back(blobs_fewer ? bl[i] : bl[s[i]], blobs_fewer ? ob[s[i]] : ob[i]);
      opts.push_back(std::move(pairs));
    }
    matched += k;
    options.push_back(std::move(opts));
  }
  return options;
}

// Solves one assignment into c.fix; goal edges are re-chosen from each fix until they no longer
// change (at most 3 solves). Returns the bearings of the last solve.
std::vector<BearingObs> solve_assignment(Candidate& c, const std::vector<Blob>& blobs, const std::vector<KnownObject>& objects,
                                         const std::optional<Pose2>& predicted) {
  Eigen::Vector2d view = predicted ? predicted->translation() : Eigen::Vector2d::Zero();
  std::vector<BearingObs> obs;
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<BearingObs> next;
    for (const auto& [bi, oj] : c.pairs) next.push_back({objects[oj].seen_from(view), blobs[bi].bearing});
    bool same = pass > 0 && next.size() == obs.size();
    for (std::size_t i = 0; same && i < next.size(); ++i) same = (next[i].landmark - obs[i].landmark).norm() < 1e-12;
    if (same) break;
    obs = std::move(next);
    c.fix = obs.size() >= 4 ? landmarks::least_squares_bearings(obs) : landmarks::total_like(obs);
    if (!c.fix.ok) break;
    view = c.fix.pose.translation();
  }
  return obs;
}

// The cost of a fix: its bearing residuals (in units of the bearing sigma), the seen distances
// against the expected ones and, with a predicted pose, the distance from it; and the bearings' RMS.
void score(Candidate& c, const std::vector<BearingObs>& obs, const std::vector<Blob>& blobs, const std::vector<KnownObject>& objects,
           const LandmarkLocalizerParams& p, const std::optional<Pose2>& predicted) {
  const double sb = deg2rad(p.bearing_sigma_deg);
  const bool use_pred = predicted.has_value() && p.prediction_sigma > 0;
  const Eigen::Vector2d P = c.fix.pose.translation();
  double ss = 0.0, cost = 0.0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const Eigen::Vector2d d = obs[i].landmark - P;
    const double r = angle_diff(std::atan2(d.y(), d.x()) - c.fix.pose.theta, obs[i].bearing);
    ss += r * r;
    const Blob& b = blobs[c.pairs[i].first];
    if (p.distance_sigma > 0 && b.has_distance) {
      const double expect = d.norm() - objects[c.pairs[i].second].half_size;
      const double e = (expect - b.distance) / (p.distance_sigma * std::max(b.distance, 0.5));
      cost += e * e;
    }
  }
  c.rms = std::sqrt(ss / static_cast<double>(obs.size()));
  cost += ss / (sb * sb);
  if (use_pred) {
    const double dp = (P - predicted->translation()).norm() / p.prediction_sigma;
    const double dt = angle_diff(c.fix.pose.theta, predicted->theta) / deg2rad(p.prediction_sigma_theta_deg);
    cost += dp * dp + dt * dt;
  }
  c.cost = cost;
}

// The next assignment: an odometer over the groups' options. False after the last one.
bool next_assignment(std::vector<std::size_t>& idx, const std::vector<GroupOptions>& options) {
  std::size_t g = 0;
  for (; g < options.size(); ++g) {
    if (++idx[g] < options[g].size()) break;
    idx[g] = 0;
  }
  return g != options.size();
}

// Refuses the best fix when another assignment as cheap puts the robot elsewhere (ambiguous), or
// when its four or more bearings disagree (inconsistent).
void refuse_doubtful(LandmarkFrame& res, const std::vector<Candidate>& cands, const Candidate& best, const LandmarkLocalizerParams& p) {
  for (const auto& c : cands) {
    if (&c == &best) continue;
    const bool elsewhere = (c.fix.pose.translation() - best.fix.pose.translation()).norm() > 0.5 ||
                           std::fabs(angle_diff(c.fix.pose.theta, best.fix.pose.theta)) > deg2rad(10.0);
    if (c.cost < best.cost + p.ambiguity_margin && elsewhere) {
      res.reason = NoFixReason::kAmbiguous;
      res.detail = "two assignments within " + std::to_string(p.ambiguity_margin) + " of the best cost";
      return;
    }
  }
  if (best.pairs.size() >= 4 && best.rms > deg2rad(p.max_bearing_rms_deg)) {
    res.reason = NoFixReason::kInconsistent;
    res.detail = "bearing RMS " + std::to_string(rad2deg(best.rms)) + " deg";
  }
}

}  // namespace

LandmarkFrame LandmarkLocalizer::solve(const std::vector<Blob>& blobs, const std::optional<Pose2>& predicted) const {
  LandmarkFrame res;
  BlobGroups groups = group_blobs(blobs, objects_, p_.skip_occluded);
  const std::vector<GroupOptions> options = pairings(groups, blobs, res.matched);
  if (res.matched < p_.min_landmarks) {
    res.reason = NoFixReason::kTooFewLandmarks;
    res.detail = std::to_string(res.matched) + " matched blobs, " + std::to_string(p_.min_landmarks) + " needed";
    return res;
  }

  std::vector<Candidate> cands;
  std::string last_reason;
  std::vector<std::size_t> idx(options.size(), 0);
  int tried = 0;
  while (tried < p_.max_assignments) {
    Candidate c;
    for (std::size_t g = 0; g < options.size(); ++g)
      for (const auto& pr : options[g][idx[g]]) c.pairs.push_back(pr);
    ++tried;
    const std::vector<BearingObs> obs = solve_assignment(c, blobs, objects_, predicted);
    if (!c.fix.ok) {
      last_reason = c.fix.reason;
    } else if (!field_.inside_floor(c.fix.pose.translation(), -p_.floor_slack)) {
      last_reason = "fix off the floor";
    } else {
      score(c, obs, blobs, objects_, p_, predicted);
      cands.push_back(std::move(c));
    }
    if (!next_assignment(idx, options)) break;
  }
  res.assignments = tried;
  if (cands.empty()) {
    res.reason = NoFixReason::kSolverRefused;
    res.detail = last_reason;
    return res;
  }
  const auto best = std::min_element(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  res.fix = best->fix;
  res.cost = best->cost;
  res.bearing_rms = best->rms;
  for (const auto& [bi, oj] : best->pairs) res.ids.push_back(objects_[oj].id);
  refuse_doubtful(res, cands, *best, p_);
  return res;
}

Estimate LandmarkLocalizer::update(const Observations& obs, const Odometry& odometry, std::optional<double>) {
  if (have_t_) since_fix_ += std::max(0.0, obs.t - last_t_);
  last_t_ = obs.t;
  have_t_ = true;
  const Pose2 pred = pose_.compose(odometry.delta);
  const bool recent = have_pose_ && since_fix_ <= p_.max_prediction_time;
  if (!obs.camera_ok) {
    last_ = LandmarkFrame{};
    last_.reason = NoFixReason::kCameraNotOk;
  } else {
    last_ = solve(obs.blobs, recent ? std::optional<Pose2>(pred) : std::nullopt);
  }
  Estimate e;
  const double sb = deg2rad(p_.bearing_sigma_deg);
  if (last_.reason == NoFixReason::kNone) {
    pose_ = last_.fix.pose;
    have_pose_ = true;
    since_fix_ = 0.0;
    e.pose = pose_;
    e.valid = true;
    e.mode = LocalizerMode::kFix;
    const double sp = sb / std::max(last_.fix.reliability, 1e-9);
    e.covariance = Eigen::Vector3d(0.5 * sp * sp, 0.5 * sp * sp, sb * sb).asDiagonal();
  } else {
    ++no_fix_total_;
    if (have_pose_) pose_ = pred;  // keep dead reckoning from the last fix going
    e.pose = pose_;
    if (p_.odometry_prediction && recent) {
      e.valid = true;
      e.mode = LocalizerMode::kOdometry;
      // Odometry error grows roughly with time since the fix; a plain, documented inflation.
      const double s = 0.1 + 0.2 * since_fix_;
      e.covariance = Eigen::Vector3d(s * s, s * s, 0.05 + 0.1 * since_fix_).asDiagonal();
    } else {
      e.valid = false;
      e.mode = LocalizerMode::kNoFix;
      e.covariance = Eigen::Matrix3d::Identity() * 1e6;
    }
  }
  e.match_error = last_.bearing_rms;
  e.extra["blobs"] = static_cast<double>(obs.blobs.size());
  e.extra["landmarks_used"] = last_.reason == NoFixReason::kNone ? static_cast<double>(last_.ids.size()) : 0.0;
  e.extra["assignments"] = last_.assignments;
  e.extra["bearing_rms_deg"] = rad2deg(last_.bearing_rms);
  e.extra["no_fix_reason"] = static_cast<double>(static_cast<int>(last_.reason));
  e.extra["no_fix_total"] = static_cast<double>(no_fix_total_);
  return e;
}

}  // namespace omniloc
