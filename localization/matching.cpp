#include "localization/matching.hpp"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <Eigen/Dense>

namespace omniloc {

const ParamList<MatchingParams>& MatchingParams::params() {
  using P = MatchingParams;
  static const ParamList<P> list = {
      positive_param("c", &P::c, 5.0, "m", "error scale of e(d) = 1 - c^2 / (c^2 + d^2) (Tribots: 250 mm)"),
      positive_param("c_start", &P::c_start, 10.0, "m", "continuation: c halves from c_start down to c (JSON default: 2 c, one smoothing stage)"),
      positive_param("step_xy", &P::step_xy, 2.0, "m", "RPROP initial step in x and y (Tribots: 40 mm)"),
      positive_param("step_theta", &P::step_theta, 1.0, "rad", "RPROP initial step in theta (Tribots: 0.1)"),
      number_param("grow", &P::grow, 1.0, 3.0, "", "RPROP step growth factor (Tribots: 1.2)"),
      number_param("shrink", &P::shrink, 0.05, 1.0, "", "RPROP step shrink factor (Tribots: 0.5)"),
      number_param("step_tol", &P::step_tol, 1e-6, 0.1, "m, rad", "RPROP stops when its steps in x, y and theta are all below this"),
      integer_param("max_iterations", &P::max_iterations, 1, 1000, "cap on RPROP iterations over all stages (Tribots 10-20, NuBot 25)"),
      integer_param("min_points", &P::min_points, 1, 10000, "fewer line points: no match, coast on odometry (NuBot > 15, CAMBADA > 5)"),
      integer_param("max_points", &P::max_points, 3, 100000, "line points evenly subsampled beyond this"),
      number_param("heading_prior", &P::heading_prior, 0.0, 1000.0, "", "weight of (theta - predicted theta)^2 (Tribots: 2.5)"),
      positive_param("point_sigma", &P::point_sigma, 2.0, "m", "line-point noise that turns the error's curvature into a covariance"),
      number_param("cell", &P::cell, 0.005, 0.5, "m", "distance-map cell (Tribots: 50 mm)"),
  };
  return list;
}

Json MatchingParams::schema() {
  const MatchingParams d;
  Json s = params_schema(params(), d);
  s.update(params_schema(filter::OdometryNoiseParams::params(filter::OdometryNoiseParams::Keys::WithRotPerMetre), d.odometry));
  return s;
}

MatchingParams MatchingParams::from_json(JsonReader& r) {
  MatchingParams p;
  for (const char* old : {"iterations", "iterations_few", "many_points"})
    if (r.has(old))
      throw ConfigError(r.child_path(old), json_brief(*r.raw(old)),
                        "no such key (removed): RPROP runs until its steps are below step_tol, at most max_iterations times");
  read_param(r, p, params(), "c");
  p.c_start = 2.0 * p.c;  // one smoothing stage unless set
  read_params(r, p, params());
  p.odometry = filter::OdometryNoiseParams::from_json(r, p.odometry, filter::OdometryNoiseParams::Keys::WithRotPerMetre);
  return p;
}

std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& pts, int n) {
  if (static_cast<int>(pts.size()) <= n) return pts;
  std::vector<Eigen::Vector2d> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) out.push_back(pts[static_cast<std::size_t>(i) * pts.size() / n]);
  return out;
}

namespace {

// Data term sum e(d) = sum 1 - c^2 / (c^2 + d^2) over the points and, with a gradient, its
// derivatives over (x, y, theta). One division per point: e sums c^2 / den, de / dd = 2 c^2 d / den^2
// and the constant factors are applied once after the loop. A template so the error-only passes
// carry no per-point test for the gradient (issue 20: the loop is the matcher's whole cost).
// Positions are in table cells: the rotation and the scaling by 1 / cell are one multiplication.
struct Terms {
  double inv = 0, gx = 0, gy = 0, gt = 0;  // 1 / den and de / dd x gradient (per cell), or their sums
  void operator+=(const Terms& o) {
    inv += o.inv;
    gx += o.gx;
    gy += o.gy;
    gt += o.gt;
  }
};

// One point's terms. Always inlined: an out-of-line call here would let the caller's locals (the
// table, the sums) escape and be reloaded from memory on every point.
template <bool kGradient>
[[gnu::always_inline]] inline Terms point_terms(const FieldMap::Table& t, double c2, double rx, double ry, double px, double py) {
  // r: the point rotated into the world frame (cells); d(point) / dtheta = (-r.y, r.x).
  const FieldMap::Sample m = t.at_cells<kGradient>(px + rx, py + ry);
  Terms u;
  u.inv = 1.0 / (c2 + m.d * m.d);
  if constexpr (kGradient) {
    const double de = m.d * u.inv * u.inv;
    u.gx = de * m.gx;
    u.gy = de * m.gy;
    u.gt = de * (m.gy * rx - m.gx * ry);  // cells cancel: gradient per cell x cells
  }
  return u;
}

template <bool kGradient>
[[gnu::always_inline]] inline double data_term(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c, Eigen::Vector3d* grad) {
  const FieldMap::Table t = map.table();
  const double c2 = c * c, a = std::cos(q.z()) * t.inv_cell, b = std::sin(q.z()) * t.inv_cell;
  const double px = (q.x() - t.x0) * t.inv_cell, py = (q.y() - t.y0) * t.inv_cell;
  const Eigen::Vector2d* P = pts.data();
  const std::size_t n = pts.size();
  Terms s;
  std::size_t k = 0;
#if defined(__SSE2__)
  // Two points per step in SSE2 lanes (every x86-64 has them): the same operations as point_terms,
  // lane by lane, so each point's terms are bit-identical; only the order of the sums differs
  // (even and odd points summed apart, then added). A pair with a point off the table goes
  // through point_terms.
  __m128d v_inv = _mm_setzero_pd(), v_gx = _mm_setzero_pd(), v_gy = _mm_setzero_pd(), v_gt = _mm_setzero_pd();
  const __m128d va = _mm_set1_pd(a), vb = _mm_set1_pd(b), vpx = _mm_set1_pd(px), vpy = _mm_set1_pd(py);
  const __m128d vlx = _mm_set1_pd(t.last_x), vly = _mm_set1_pd(t.last_y), vc2 = _mm_set1_pd(c2), one = _mm_set1_pd(1.0), zero = _mm_setzero_pd();
  for (; k + 1 < n; k += 2) {
    const __m128d p0 = _mm_loadu_pd(P[k].data()), p1 = _mm_loadu_pd(P[k + 1].data());
    const __m128d ox = _mm_unpacklo_pd(p0, p1), oy = _mm_unpackhi_pd(p0, p1);
    const __m128d rx = _mm_sub_pd(_mm_mul_pd(va, ox), _mm_mul_pd(vb, oy));
    const __m128d ry = _mm_add_pd(_mm_mul_pd(vb, ox), _mm_mul_pd(va, oy));
    const __m128d fx = _mm_add_pd(vpx, rx), fy = _mm_add_pd(vpy, ry);
    const __m128d on = _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(fx, zero), _mm_cmpge_pd(fy, zero)), _mm_and_pd(_mm_cmplt_pd(fx, vlx), _mm_cmplt_pd(fy, vly)));
    if (_mm_movemask_pd(on) != 3) [[unlikely]] {
      alignas(16) double rxs[2], rys[2];
      _mm_store_pd(rxs, rx);
      _mm_store_pd(rys, ry);
      s += point_terms<kGradient>(t, c2, rxs[0], rys[0], px, py);
      s += point_terms<kGradient>(t, c2, rxs[1], rys[1], px, py);
      continue;
    }
    const __m128i ij_x = _mm_cvttpd_epi32(fx), ij_y = _mm_cvttpd_epi32(fy);  // truncation = floor: fx, fy >= 0
    const __m128d ax = _mm_sub_pd(fx, _mm_cvtepi32_pd(ij_x)), ay = _mm_sub_pd(fy, _mm_cvtepi32_pd(ij_y));
    const double* r0 = t.cells + _mm_cvtsi128_si32(ij_y) * t.nx + _mm_cvtsi128_si32(ij_x);
    const double* r1 = t.cells + _mm_cvtsi128_si32(_mm_shuffle_epi32(ij_y, 1)) * t.nx + _mm_cvtsi128_si32(_mm_shuffle_epi32(ij_x, 1));
    const __m128d top0 = _mm_loadu_pd(r0), bot0 = _mm_loadu_pd(r0 + t.nx), top1 = _mm_loadu_pd(r1), bot1 = _mm_loadu_pd(r1 + t.nx);
    const __m128d d00 = _mm_unpacklo_pd(top0, top1), d10 = _mm_unpackhi_pd(top0, top1);
    const __m128d d01 = _mm_unpacklo_pd(bot0, bot1), d11 = _mm_unpackhi_pd(bot0, bot1);
    const __m128d dx0 = _mm_sub_pd(d10, d00), dx1 = _mm_sub_pd(d11, d01);
    const __m128d lo = _mm_add_pd(d00, _mm_mul_pd(ax, dx0)), hi = _mm_add_pd(d01, _mm_mul_pd(ax, dx1));
    const __m128d hl = _mm_sub_pd(hi, lo);
    const __m128d d = _mm_add_pd(lo, _mm_mul_pd(ay, hl));
    const __m128d inv = _mm_div_pd(one, _mm_add_pd(vc2, _mm_mul_pd(d, d)));
    v_inv = _mm_add_pd(v_inv, inv);
    if constexpr (kGradient) {
      const __m128d gx = _mm_add_pd(dx0, _mm_mul_pd(ay, _mm_sub_pd(dx1, dx0))), gy = hl;
      const __m128d de = _mm_mul_pd(_mm_mul_pd(d, inv), inv);
      v_gx = _mm_add_pd(v_gx, _mm_mul_pd(de, gx));
      v_gy = _mm_add_pd(v_gy, _mm_mul_pd(de, gy));
      v_gt = _mm_add_pd(v_gt, _mm_mul_pd(de, _mm_sub_pd(_mm_mul_pd(gy, rx), _mm_mul_pd(gx, ry))));
    }
  }
  const auto lanes = [](__m128d v) { return _mm_cvtsd_f64(v) + _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
  s.inv += lanes(v_inv);
  s.gx += lanes(v_gx);
  s.gy += lanes(v_gy);
  s.gt += lanes(v_gt);
#endif
  for (; k < n; ++k) s += point_terms<kGradient>(t, c2, a * P[k].x() - b * P[k].y(), b * P[k].x() + a * P[k].y(), px, py);
  if constexpr (kGradient) *grad = 2.0 * c2 * Eigen::Vector3d(s.gx * t.inv_cell, s.gy * t.inv_cell, s.gt);
  return static_cast<double>(n) - c2 * s.inv;
}

// Compiled twice where the compiler can (GCC on x86-64): for AVX2 machines, whose three-operand
// instructions drop most of SSE2's register copies, and for any x86-64; picked once at load time.
// Neither version contracts to FMA (AVX2 alone does not enable it), so both give the same bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
double data_term(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c, Eigen::Vector3d* grad) {
  return grad ? data_term<true>(map, pts, q, c, grad) : data_term<false>(map, pts, q, c, nullptr);
}

}  // namespace

double match_error(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& pose, double c) {
  if (pts.empty()) return 1.0;
  return data_term(map, pts, {pose.x, pose.y, pose.theta}, c, nullptr) / pts.size();
}

MatchResult rprop_match(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Pose2& start, const MatchingParams& p,
                        int max_iterations, std::optional<double> prior_theta, std::vector<double>* trace) {
  Eigen::Vector3d q(start.x, start.y, start.theta);
  Eigen::Vector3d step(p.step_xy, p.step_xy, p.step_theta), prev = Eigen::Vector3d::Zero();
  const Eigen::Vector3d max_step(1.0, 1.0, 0.5), min_step(1e-6, 1e-6, 1e-6);
  MatchResult r;
  r.points = static_cast<int>(pts.size());
  // Continuation: stages with c = c_start, c_start / 2, ... down to c. Each stage runs until its
  // RPROP steps are all below its tolerance (step_tol scaled by c_stage / c: a smoothed stage only
  // brings the pose into the final basin, its own minimum is off the final one by more than that)
  // or until its share of the cap; the final stage gets every iteration the earlier ones left, so
  // at least its own share, however the cap and the number of stages compare.
  int stages = 1;
  if (p.c_start > p.c) stages = static_cast<int>(std::ceil(std::log2(p.c_start / p.c))) + 1;
  const int cap = std::max(1, max_iterations);
  const int share = std::max(1, cap / stages);
  for (int stage = 0; stage < stages && r.iterations < cap; ++stage) {
    const bool last = stage == stages - 1;
    const double c = last ? p.c : std::max(p.c, p.c_start * std::pow(0.5, stage));
    const double tol = p.step_tol * c / p.c;
    const int end = last ? cap : std::min(cap, r.iterations + share);
    // A new error function: the last stage's gradient signs say nothing about this one's. The steps
    // carry over: the minimum moves by less than they have shrunk to (restarting them at step0 cost
    // more iterations and lost cold starts on the test of issue 17).
    prev.setZero();
    while (r.iterations < end) {
      Eigen::Vector3d g;
      data_term(map, pts, q, c, &g);
      if (trace) trace->push_back(pts.empty() ? 1.0 : data_term(map, pts, q, p.c, nullptr) / pts.size());
      if (prior_theta && p.heading_prior > 0) g.z() += 2.0 * p.heading_prior * angle_diff(q.z(), *prior_theta);
      for (int k = 0; k < 3; ++k) {
        // iRPROP-: on a sign change shrink the step and skip this update.
        if (g[k] * prev[k] > 0) step[k] = std::min(step[k] * p.grow, max_step[k]);
        else if (g[k] * prev[k] < 0) {
          step[k] = std::max(step[k] * p.shrink, min_step[k]);
          g[k] = 0;
        }
        if (g[k] > 0) q[k] -= step[k];
        else if (g[k] < 0) q[k] += step[k];
        prev[k] = g[k];
      }
      ++r.iterations;
      if (step.maxCoeff() < tol) {
        if (last) r.converged = true;
        break;
      }
    }
  }
  r.pose = Pose2(q.x(), q.y(), q.z());
  r.error = pts.empty() ? 1.0 : data_term(map, pts, q, p.c, nullptr) / pts.size();
  if (trace) trace->push_back(r.error);
  // Curvature of the data term by central differences of its gradient. Near the optimum
  // e(d) ~ d^2 / c^2, so the Gauss-Newton information of points with noise sigma is H c^2 / (2 sigma^2).
  Eigen::Matrix3d H;
  const Eigen::Vector3d h(0.01, 0.01, 0.005);
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d qp = q, qm = q, gp, gm;
    qp[k] += h[k];
    qm[k] -= h[k];
    data_term(map, pts, qp, p.c, &gp);
    data_term(map, pts, qm, p.c, &gm);
    H.col(k) = (gp - gm) / (2 * h[k]);
  }
  H = 0.5 * (H + H.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H * (p.c * p.c / (2 * p.point_sigma * p.point_sigma)));
  Eigen::Vector3d ev = es.eigenvalues();
  // A flat direction (all points on one line) gets a large variance instead of an infinite one.
  for (int k = 0; k < 3; ++k) ev[k] = 1.0 / std::max(ev[k], 1.0);
  r.covariance = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  return r;
}

MatchingLocalizer::MatchingLocalizer(const Field& field, const MatchingParams& p, const std::string& cache_dir)
    : p_(p), map_(field, p.cell, cache_dir) {}

void MatchingLocalizer::reset(const std::optional<Pose2>& start) {
  started_ = start.has_value();
  kf_.reset(start.value_or(Pose2()), Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.02 * 0.02).asDiagonal());
}

Estimate MatchingLocalizer::track(const Observations& obs, const Odometry& odometry) {
  kf_.predict(odometry.delta, p_.odometry);
  Estimate e;
  const std::vector<Eigen::Vector2d> pts = subsample(obs.line_points, p_.max_points);
  e.extra["points"] = static_cast<double>(pts.size());
  if (!obs.camera_ok || static_cast<int>(pts.size()) < p_.min_points) {
    e.mode = LocalizerMode::kCoasting;  // no usable vision: odometry only, no jump
    e.pose = kf_.pose();
    e.covariance = kf_.covariance();
    e.valid = started_;
    e.match_error = 1.0;  // the worst possible mean error: nothing matched
    return e;
  }
  // RPROP's first steps: one standard deviation of the prediction, at most Tribots' steps (a fresh
  // reset's 5 cm) and at least 4 step_tol. Tribots' 0.1 rad first step throws a prediction good to
  // 0.01 rad off by 0.09 rad, and halving it back below step_tol takes about a dozen iterations
  // (23 instead of 14 on BM_MatchingUpdate/200).
  MatchingParams p = p_;
  const Eigen::Matrix3d& P = kf_.covariance();
  p.step_xy = std::clamp(std::sqrt(std::max(P(0, 0), P(1, 1))), 4 * p_.step_tol, std::max(p_.step_xy, 4 * p_.step_tol));
  p.step_theta = std::clamp(std::sqrt(P(2, 2)), 4 * p_.step_tol, std::max(p_.step_theta, 4 * p_.step_tol));
  const MatchResult m = rprop_match(map_, pts, kf_.pose(), p, p.max_iterations, kf_.pose().theta);
  kf_.update(m.pose, m.covariance);
  e.pose = kf_.pose();
  e.covariance = kf_.covariance();
  e.valid = started_;
  e.mode = LocalizerMode::kTracking;
  e.match_error = m.error;
  e.extra["iterations"] = m.iterations;
  e.extra["match_sd_xy"] = std::sqrt(0.5 * (m.covariance(0, 0) + m.covariance(1, 1)));
  return e;
}

Estimate MatchingLocalizer::update(const Observations& obs, const Odometry& odometry, std::optional<double>) { return track(obs, odometry); }

}  // namespace omniloc
