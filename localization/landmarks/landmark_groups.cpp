#include "localization/landmarks/landmark_groups.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "localization/landmarks/landmark_solvers.hpp"

namespace omniloc::landmarks {

Eigen::Vector2d LandmarkSighting::relative() const { return distance * Eigen::Vector2d(std::cos(bearing), std::sin(bearing)); }

GroupFeature group_feature(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& p3) {
  const Eigen::Vector2d d12 = p2 - p1, d13 = p3 - p1;
  GroupFeature f;
  f.d12 = d12.norm();
  f.d13 = d13.norm();
  // Signed angle from d12 to d13: atan2(cross, dot), anticlockwise positive, in (-pi, pi].
  f.angle = wrap_angle(std::atan2(d12.x() * d13.y() - d12.y() * d13.x(), d12.dot(d13)));
  return f;
}

std::vector<LandmarkGroup> form_groups(std::span<const LandmarkSighting> s) {
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (std::isfinite(s[i].distance) && std::isfinite(s[i].bearing) && s[i].distance >= 0.0) usable.push_back(i);
  std::vector<LandmarkGroup> groups;
  const std::size_t n = usable.size();
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      for (std::size_t c = b + 1; c < n; ++c) {
        std::array<std::size_t, 3> m{usable[a], usable[b], usable[c]};
        if (s[m[0]].colour == s[m[1]].colour || s[m[0]].colour == s[m[2]].colour || s[m[1]].colour == s[m[2]].colour) continue;
        std::sort(m.begin(), m.end(), [&](std::size_t x, std::size_t y) { return s[x].colour < s[y].colour; });
        LandmarkGroup g;
        g.member = m;
        for (std::size_t k = 0; k < 3; ++k) g.colour[k] = s[m[k]].colour;
        g.feature = group_feature(s[m[0]].relative(), s[m[1]].relative(), s[m[2]].relative());
        groups.push_back(g);
      }
  return groups;
}

bool groups_match(const LandmarkGroup& a, const LandmarkGroup& b, const GroupMatchParams& p) {
  if (a.colour != b.colour) return false;
  return std::fabs(a.feature.d12 - b.feature.d12) <= p.max_distance_diff && std::fabs(a.feature.d13 - b.feature.d13) <= p.max_distance_diff &&
         std::fabs(angle_diff(a.feature.angle, b.feature.angle)) <= p.max_angle_diff;
}

double feature_cost(const GroupFeature& a, const GroupFeature& b, const GroupMatchParams& p) {
  const double u = (a.d12 - b.d12) / p.max_distance_diff;
  const double v = (a.d13 - b.d13) / p.max_distance_diff;
  const double w = angle_diff(a.angle, b.angle) / p.max_angle_diff;
  return u * u + v * v + w * w;
}

std::vector<int> match_groups(std::span<const LandmarkGroup> previous, std::span<const LandmarkGroup> current, const GroupMatchParams& p) {
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;  // (cost, current, previous)
  for (std::size_t i = 0; i < current.size(); ++i)
    for (std::size_t j = 0; j < previous.size(); ++j)
      if (groups_match(current[i], previous[j], p)) pairs.emplace_back(feature_cost(current[i].feature, previous[j].feature, p), i, j);
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> result(current.size(), -1);
  std::vector<bool> taken(previous.size(), false);
  for (const auto& [cost, i, j] : pairs) {
    if (result[i] >= 0 || taken[j]) continue;
    result[i] = static_cast<int>(j);
    taken[j] = true;
  }
  return result;
}

Fix group_fix(const LandmarkGroup& g, std::span<const LandmarkSighting> sightings, const std::array<Eigen::Vector2d, 3>& world) {
  std::array<BearingObs, 3> obs;
  for (std::size_t k = 0; k < 3; ++k) {
    if (g.member[k] >= sightings.size()) return no_fix("group member index outside the frame's sightings");
    obs[k].landmark = world[k];
    obs[k].bearing = sightings[g.member[k]].bearing;
  }
  return circle_intersection_003(obs);
}

PlausibleRegion PlausibleRegion::from_path(const Eigen::Vector2d& start, const Eigen::Vector2d& goal, double margin) {
  PlausibleRegion r;
  r.centre = 0.5 * (start + goal);
  r.radius = 0.5 * (goal - start).norm() + std::max(0.0, margin);
  return r;
}

bool PlausibleRegion::contains(const Eigen::Vector2d& p) const { return radius < 0.0 || (p - centre).norm() <= radius; }

Pose2 mean_pose(std::span<const Pose2> poses) {
  if (poses.empty()) return Pose2();
  double x = 0, y = 0, c = 0, s = 0;
  for (const Pose2& q : poses) {
    x += q.x;
    y += q.y;
    c += std::cos(q.theta);
    s += std::sin(q.theta);
  }
  const double n = static_cast<double>(poses.size());
  return Pose2(x / n, y / n, std::atan2(s, c));
}

FixVoter::FixVoter(const Pose2& start, const VotingParams& params) : params_(params), position_(start) {}

VoteResult FixVoter::vote(std::span<const Pose2> fixes, const PlausibleRegion& region) {
  VoteResult r;
  const std::size_t n = fixes.size();
  r.fix_votes.assign(n, 1);
  int maxvote = -1;
  bool visflag = false;
  const auto agree = [&](const Pose2& a, const Pose2& b) {
    return std::hypot(a.x - b.x, a.y - b.y) < params_.position_tol && std::fabs(angle_diff(a.theta, b.theta)) < params_.heading_tol;
  };
  std::vector<Pose2> cluster;
  std::vector<int> members;
  for (std::size_t i = 0; i < n; ++i) {
    cluster.assign(1, fixes[i]);
    members.assign(1, static_cast<int>(i));
    for (std::size_t j = params_.later_only ? i + 1 : 0; j < n; ++j)
      if (j != i && agree(fixes[i], fixes[j])) {
        cluster.push_back(fixes[j]);
        members.push_back(static_cast<int>(j));
      }
    const int vote = static_cast<int>(cluster.size());
    r.fix_votes[i] = vote;
    if (vote > maxvote || !visflag) {
      const Pose2 average = mean_pose(cluster);
      maxvote = vote;
      const bool inside = region.contains(average.translation());
      if (inside || deadlock_ > params_.deadlock_limit) {
        visflag = true;
        r.forced = !inside;
        r.votes = vote;
        r.members = members;
        position_ = average;
      }
    }
  }
  deadlock_ = visflag ? 0 : deadlock_ + 1;
  r.accepted = visflag;
  r.position = position_;
  r.deadlock = deadlock_;
  return r;
}

GroupLocalizer::GroupLocalizer(const Pose2& start, const GroupLocalizerParams& params)
    : params_(params), voter_(start, params.voting), estimate_(start) {}

GroupFrameResult GroupLocalizer::update(std::span<const LandmarkSighting> sightings, const PlausibleRegion& region) {
  GroupFrameResult out;
  const std::vector<LandmarkGroup> groups = form_groups(sightings);
  std::vector<LandmarkGroup> prev;
  prev.reserve(candidates_.size());
  for (const auto& t : candidates_) prev.push_back(t.group);
  const std::vector<int> match = match_groups(prev, groups, params_.match);

  out.groups.resize(groups.size());
  for (std::size_t i = 0; i < groups.size(); ++i) {
    TrackedGroup& t = out.groups[i];
    t.group = groups[i];
    t.previous = match[i];
    if (match[i] < 0) continue;
    const TrackedGroup& p = candidates_[static_cast<std::size_t>(match[i])];
    t.world = p.world;
    t.id = p.id;
    t.fix = group_fix(t.group, sightings, t.world);
    if (t.fix.ok) out.fixes.push_back(t.fix.pose);
  }

  if (params_.use_voting) {
    out.vote = voter_.vote(out.fixes, region);
    estimate_ = out.vote.position;
  } else {
    out.vote.accepted = !out.fixes.empty();
    if (out.vote.accepted) estimate_ = mean_pose(out.fixes);
    out.vote.position = estimate_;
    out.vote.fix_votes.assign(out.fixes.size(), 0);
  }
  out.estimate = estimate_;

  // New groups: global coordinates from the robot position just decided and this frame's sightings.
  std::vector<TrackedGroup> new_memory;
  for (TrackedGroup& t : out.groups) {
    if (t.previous >= 0) continue;
    for (std::size_t k = 0; k < 3; ++k) t.world[k] = estimate_.transform(sightings[t.group.member[k]].relative());
    t.id = next_id_++;
    if (params_.remember_groups) {
      // Remembered with the feature of its global coordinates (equal to the sighted one: a rigid motion).
      TrackedGroup m = t;
      m.group.feature = group_feature(t.world[0], t.world[1], t.world[2]);
      m.fix = Fix();
      new_memory.push_back(std::move(m));
    }
  }
  if (params_.remember_groups)
    candidates_.insert(candidates_.end(), new_memory.begin(), new_memory.end());
  else
    candidates_ = out.groups;
  return out;
}

}  // namespace omniloc::landmarks
