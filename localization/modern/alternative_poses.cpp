#include "localization/modern/alternative_poses.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/angles.hpp"
#include "localization/match_data_term.hpp"
#include "localization/modern/hypothesis_set.hpp"

namespace omniloc::modern {

double fit_score(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c) {
  if (pts.empty()) return 1.0;
  return match_data_term(map, pts, q, c, nullptr) / static_cast<double>(pts.size());
}

namespace {

// Nelder-Mead over the first `dims` coordinates of q (2: x, y; 3: x, y, theta).
Candidate nelder_mead(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& start, int dims, double c,
                      const Eigen::Vector3d& step, int max_eval, double tol) {
  const auto f = [&](const Eigen::Vector3d& q) { return fit_score(map, pts, q, c); };
  std::array<Eigen::Vector3d, 4> x;
  std::array<double, 4> fx{};
  const int n = dims;
  x[0] = start;
  for (int k = 0; k < n; ++k) {
    x[static_cast<std::size_t>(k + 1)] = start;
    x[static_cast<std::size_t>(k + 1)][k] += step[k];
  }
  int evals = 0;
  for (int k = 0; k <= n; ++k) fx[static_cast<std::size_t>(k)] = f(x[static_cast<std::size_t>(k)]), ++evals;
  std::array<int, 4> order{0, 1, 2, 3};
  while (evals < max_eval) {
    // Insertion sort of at most four vertices by score (std::sort on a part of the array trips
    // GCC 12's array-bounds warning).
    for (int a = 1; a <= n; ++a)
      for (int b = a; b > 0 && fx[static_cast<std::size_t>(order[static_cast<std::size_t>(b)])] < fx[static_cast<std::size_t>(order[static_cast<std::size_t>(b - 1)])]; --b)
        std::swap(order[static_cast<std::size_t>(b)], order[static_cast<std::size_t>(b - 1)]);
    const auto at = [&](int r) -> std::size_t { return static_cast<std::size_t>(order[static_cast<std::size_t>(r)]); };
    // Size: the largest distance from the best vertex (theta counted like metres: 1 rad ~ 1 m at
    // the typical point range, the same scale the score sees).
    double size = 0.0;
    for (int k = 1; k <= n; ++k) size = std::max(size, (x[at(k)] - x[at(0)]).cwiseAbs().maxCoeff());
    if (size < tol) break;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < n; ++k) centroid += x[at(k)];
    centroid /= n;
    const std::size_t worst = at(n);
    const Eigen::Vector3d xr = centroid + (centroid - x[worst]);
    const double fr = f(xr);
    ++evals;
    if (fr < fx[at(0)]) {
      const Eigen::Vector3d xe = centroid + 2.0 * (centroid - x[worst]);
      const double fe = f(xe);
      ++evals;
      if (fe < fr) x[worst] = xe, fx[worst] = fe;
      else x[worst] = xr, fx[worst] = fr;
    } else if (fr < fx[at(n - 1)]) {
      x[worst] = xr, fx[worst] = fr;
    } else {
      const bool outside = fr < fx[worst];
      const Eigen::Vector3d xc = outside ? Eigen::Vector3d(centroid + 0.5 * (xr - centroid)) : Eigen::Vector3d(centroid + 0.5 * (x[worst] - centroid));
      const double fc = f(xc);
      ++evals;
      if (fc < std::min(fr, fx[worst])) x[worst] = xc, fx[worst] = fc;
      else {
        for (int k = 1; k <= n; ++k) {
          x[at(k)] = x[at(0)] + 0.5 * (x[at(k)] - x[at(0)]);
          fx[at(k)] = f(x[at(k)]);
          ++evals;
        }
      }
    }
  }
  std::size_t b = 0;
  for (int k = 1; k <= n; ++k)
    if (fx[static_cast<std::size_t>(k)] < fx[b]) b = static_cast<std::size_t>(k);
  Candidate out;
  out.pose = x[b];
  out.pose.z() = wrap_angle(out.pose.z());
  out.score = fx[b];
  return out;
}

}  // namespace

Candidate simplex_fit(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& start, const AlternativePoseParams& p,
                      std::optional<double> heading) {
  const Eigen::Vector3d step(p.step_xy, p.step_xy, p.step_theta);
  Eigen::Vector3d q = start;
  int dims = 3;
  if (heading) {
    q.z() = *heading;
    dims = 2;
  }
  Candidate wide = nelder_mead(map, pts, q, dims, p.c_wide, step, p.max_evaluations, p.tolerance * p.c_wide / p.c);
  // The final stage over all three coordinates from a simplex a third the size: the wide stage left
  // the pose within the final score's basin.
  Candidate fine = nelder_mead(map, pts, wide.pose, 3, p.c, step / 3.0, p.max_evaluations, p.tolerance);
  return fine;
}

AlternativePoses::AlternativePoses(const AlternativePoseParams& p, double half_x, double half_y, std::uint64_t seed)
    : p_(p), half_x_(half_x), half_y_(half_y), rng_(Rng::stream(seed, "localizer/ukf_mh/alternatives")) {}

void AlternativePoses::move(const Pose2& d) {
  for (auto& c : pool_) {
    const Pose2 q = Pose2(c.pose.x(), c.pose.y(), c.pose.z()).compose(d);
    c.pose = Eigen::Vector3d(q.x, q.y, q.theta);
  }
}

const std::vector<Candidate>& AlternativePoses::search(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading,
                                                       int restarts, const std::vector<Eigen::Vector3d>& extra) {
  std::vector<Candidate> found;
  for (const auto& c : pool_) found.push_back(simplex_fit(map, pts, c.pose, p_, std::nullopt));
  for (const auto& e : extra) found.push_back(simplex_fit(map, pts, e, p_, std::nullopt));
  if (restarts > 0) {
    // Screening: every restart drawn (the same number of draws whatever the scores, so the stream
    // stays in step), scored once at the wide c.
    std::vector<Candidate> screened;
    screened.reserve(static_cast<std::size_t>(restarts));
    for (int k = 0; k < restarts; ++k) {
      const double x = rng_.uniform(-half_x_, half_x_), y = rng_.uniform(-half_y_, half_y_), th = rng_.uniform(-kPi, kPi);
      Candidate c;
      c.pose = Eigen::Vector3d(x, y, heading ? *heading : th);
      c.score = fit_score(map, pts, c.pose, p_.c_wide);
      screened.push_back(c);
    }
    const std::size_t keep = std::min<std::size_t>(static_cast<std::size_t>(p_.refined), screened.size());
    std::partial_sort(screened.begin(), screened.begin() + static_cast<std::ptrdiff_t>(keep), screened.end(),
                      [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
    for (std::size_t k = 0; k < keep; ++k) found.push_back(simplex_fit(map, pts, screened[k].pose, p_, heading));
  }
  std::stable_sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
  pool_.clear();
  for (const auto& c : found) {
    bool dup = false;
    for (const auto& k : pool_) dup = dup || same_basin(c.pose, k.pose, p_.distinct_xy, p_.distinct_theta);
    if (!dup) pool_.push_back(c);
    if (static_cast<int>(pool_.size()) >= p_.pool) break;
  }
  return pool_;
}

}  // namespace omniloc::modern
