#include "localization/modern/hypothesis_set.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"

namespace omniloc::modern {

bool same_basin(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double xy, double theta) {
  return std::hypot(a.x() - b.x(), a.y() - b.y()) < xy && std::fabs(angle_diff(a.z(), b.z())) < theta;
}

Eigen::Vector3d twin(const Eigen::Vector3d& q) { return {-q.x(), -q.y(), wrap_angle(q.z() + kPi)}; }

namespace {
// True when a should give way to b: less valid, or as valid and younger.
bool weaker(const Hypothesis& a, const Hypothesis& b) { return a.validity < b.validity || (a.validity == b.validity && a.id > b.id); }
}  // namespace

void merge(std::vector<Hypothesis>& set, const HypothesisSetParams& p, bool twins_equal, std::int64_t lead, double hysteresis) {
  const auto gives_way = [&](const Hypothesis& a, const Hypothesis& b) {
    if (static_cast<std::int64_t>(a.id) == lead) return b.validity >= a.validity + hysteresis;
    if (static_cast<std::int64_t>(b.id) == lead) return a.validity < b.validity + hysteresis;
    return weaker(a, b);
  };
  std::vector<bool> gone(set.size(), false);
  for (std::size_t i = 0; i < set.size(); ++i)
    for (std::size_t j = 0; j < set.size(); ++j) {
      if (i == j || gone[i] || gone[j]) continue;
      const Eigen::Vector3d& a = set[i].ukf.mean();
      const Eigen::Vector3d& b = set[j].ukf.mean();
      const bool close = same_basin(a, b, p.merge_xy, p.merge_theta) || (twins_equal && same_basin(a, twin(b), p.merge_xy, p.merge_theta));
      if (close && gives_way(set[i], set[j])) gone[i] = true;
    }
  std::vector<Hypothesis> kept;
  for (std::size_t i = 0; i < set.size(); ++i)
    if (!gone[i]) kept.push_back(set[i]);
  set.swap(kept);
}

void prune(std::vector<Hypothesis>& set, const HypothesisSetParams& p) {
  if (set.size() <= 1) return;
  double top = 0.0;
  for (const auto& h : set) top = std::max(top, h.validity);
  std::vector<Hypothesis> kept;
  for (const auto& h : set)
    if (h.age < p.prune_age || (h.validity >= p.prune_validity && h.validity >= top - p.prune_gap)) kept.push_back(h);
  if (kept.empty()) kept.push_back(set[static_cast<std::size_t>(best(set, -1, 0.0))]);
  set.swap(kept);
}

bool insert(std::vector<Hypothesis>& set, Hypothesis h, const HypothesisSetParams& p) {
  if (static_cast<int>(set.size()) < p.max_hypotheses) {
    set.push_back(std::move(h));
    return true;
  }
  std::size_t worst = 0;
  for (std::size_t i = 1; i < set.size(); ++i)
    if (weaker(set[i], set[worst])) worst = i;
  if (set[worst].validity > h.validity) return false;
  set[worst] = std::move(h);
  return true;
}

int best(const std::vector<Hypothesis>& set, int current, double hysteresis) {
  int b = -1;
  for (std::size_t i = 0; i < set.size(); ++i)
    if (b < 0 || weaker(set[static_cast<std::size_t>(b)], set[i])) b = static_cast<int>(i);
  if (current >= 0 && current < static_cast<int>(set.size()) && b != current &&
      set[static_cast<std::size_t>(b)].validity < set[static_cast<std::size_t>(current)].validity + hysteresis)
    return current;
  return b;
}

}  // namespace omniloc::modern
