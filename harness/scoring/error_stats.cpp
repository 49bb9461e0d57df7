#include "harness/scoring/error_stats.hpp"

#include <algorithm>
#include <cmath>

namespace omniloc::harness {

namespace {
AxisStats stats(const std::vector<double>& v) {
  AxisStats a;
  if (v.empty()) return a;
  double s = 0, s2 = 0, m = 0;
  for (double x : v) {
    s += x;
    m = std::max(m, x);
  }
  a.mean = s / v.size();
  for (double x : v) s2 += (x - a.mean) * (x - a.mean);
  a.std = std::sqrt(s2 / v.size());
  a.max = m;
  return a;
}
}  // namespace

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = p / 100.0 * (v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (pos - i) * (v[i + 1] - v[i]);
}

ErrorSummary summarize(const std::vector<FrameError>& errors) {
  ErrorSummary s;
  s.frames = errors.size();
  if (errors.empty()) return s;
  std::vector<double> ax, ay, at, pos;
  double se2 = 0, st2 = 0, sum_pos = 0;
  for (const auto& e : errors) {
    ax.push_back(std::fabs(e.ex) * 100.0);
    ay.push_back(std::fabs(e.ey) * 100.0);
    at.push_back(std::fabs(e.eth));
    pos.push_back(std::hypot(e.ex, e.ey));
    sum_pos += pos.back();
    se2 += e.ex * e.ex + e.ey * e.ey;
    st2 += e.eth * e.eth;
  }
  s.x_cm = stats(ax);
  s.y_cm = stats(ay);
  s.theta_rad = stats(at);
  s.pos_mean_m = sum_pos / errors.size();
  s.pos_rmse_m = std::sqrt(se2 / errors.size());
  s.theta_rmse_rad = std::sqrt(st2 / errors.size());
  s.pos_p50_m = percentile(pos, 50);
  s.pos_p90_m = percentile(pos, 90);
  s.pos_p95_m = percentile(pos, 95);
  s.pos_max_m = *std::max_element(pos.begin(), pos.end());
  return s;
}

Json to_json(const ErrorSummary& s) {
  // Over no frame a statistic is not a number: null, never the zeros ErrorSummary holds.
  const auto v = [&](double x) { return s.frames ? Json(x) : Json(nullptr); };
  auto axis = [&](const AxisStats& a) { return Json{{"mean", v(a.mean)}, {"std", v(a.std)}, {"max", v(a.max)}}; };
  return Json{{"frames", s.frames},
              {"x_cm", axis(s.x_cm)},
              {"y_cm", axis(s.y_cm)},
              {"theta_rad", axis(s.theta_rad)},
              {"position_m", {{"mean", v(s.pos_mean_m)}, {"rmse", v(s.pos_rmse_m)}, {"p50", v(s.pos_p50_m)}, {"p90", v(s.pos_p90_m)}, {"p95", v(s.pos_p95_m)}, {"max", v(s.pos_max_m)}}},
              {"theta_rmse_rad", v(s.theta_rmse_rad)}};
}

}  // namespace omniloc::harness
