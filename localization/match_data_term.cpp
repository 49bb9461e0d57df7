#include "localization/match_data_term.hpp"

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <string>

#if defined(__x86_64__) && defined(__SSE2__)
#include <immintrin.h>
#define OMNILOC_X86 1
#endif

namespace omniloc {
namespace {

// Positions are in table cells: the rotation and the scaling by 1 / cell are one multiplication.
// One division per point: E sums c^2 / den (den = c^2 + d^2), dE / dd = 2 c^2 d / den^2; the
// constant factors are applied once after the loop.
struct Terms {
  double inv = 0, gx = 0, gy = 0, gt = 0;  // 1 / den and dd-weighted gradient (per cell), or their sums
  void operator+=(const Terms& o) {
    inv += o.inv;
    gx += o.gx;
    gy += o.gy;
    gt += o.gt;
  }
};

struct Setup {
  FieldMap::Table t;  // a local copy: its fields stay in registers
  double c2, a, b;    // c^2; cos(theta) / cell, sin(theta) / cell
  double px, py;      // the pose's position in table cells
};

// One point's terms. Always inlined: an out-of-line call would let the caller's locals (the table,
// the sums) escape and be reloaded from memory on every point.
template <bool kGradient>
[[gnu::always_inline]] inline Terms point_terms(const Setup& u, double rx, double ry, double w) {
  // r: the point rotated into the world frame (cells); d(point) / dtheta = (-r.y, r.x).
  const FieldMap::Sample m = u.t.at_cells<kGradient>(u.px + rx, u.py + ry);
  Terms o;
  const double inv = 1.0 / (u.c2 + m.d * m.d);
  o.inv = w * inv;  // w = 1 (unweighted) multiplies exactly: the same bits as without weights
  if constexpr (kGradient) {
    const double de = m.d * o.inv * inv;
    o.gx = de * m.gx;
    o.gy = de * m.gy;
    o.gt = de * (m.gy * rx - m.gx * ry);  // cells cancel: gradient per cell x cells
  }
  return o;
}

template <bool kGradient>
[[gnu::always_inline]] inline void point(const Setup& u, const Eigen::Vector2d& o, double w, Terms* s) {
  *s += point_terms<kGradient>(u, u.a * o.x() - u.b * o.y(), u.b * o.x() + u.a * o.y(), w);
}

// total_weight: the number of points, or the sum of their weights.
double finish(const Setup& u, double total_weight, const Terms& s, Eigen::Vector3d* grad) {
  if (grad) *grad = 2.0 * u.c2 * Eigen::Vector3d(s.gx * u.t.inv_cell, s.gy * u.t.inv_cell, s.gt);
  return total_weight - u.c2 * s.inv;
}

#if defined(OMNILOC_X86)
// Two points in SSE2 lanes: the operations of point_terms lane by lane, so each point's terms are
// bit-identical to it; lane sums (even and odd points apart) are added to the scalar sums at the
// end. A pair with a point off the table (or on the last row / column) goes through point_terms.
struct Lanes {
  __m128d inv = _mm_setzero_pd(), gx = _mm_setzero_pd(), gy = _mm_setzero_pd(), gt = _mm_setzero_pd();
  void add_to(Terms* s) const {
    const auto sum = [](__m128d v) { return _mm_cvtsd_f64(v) + _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); };
    s->inv += sum(inv);
    s->gx += sum(gx);
    s->gy += sum(gy);
    s->gt += sum(gt);
  }
};

// The lane terms of two points from their table positions (fx, fy, both lanes on the table) and
// rotated offsets (rx, ry), given the four corner values of each point's cell.
template <bool kGradient>
[[gnu::always_inline]] inline void lane_terms(__m128d c2, __m128d w, __m128d fx, __m128d fy, __m128d rx, __m128d ry, __m128i ix, __m128i iy,
                                              __m128d d00, __m128d d10, __m128d d01, __m128d d11, Lanes* acc) {
  const __m128d ax = _mm_sub_pd(fx, _mm_cvtepi32_pd(ix)), ay = _mm_sub_pd(fy, _mm_cvtepi32_pd(iy));
  const __m128d dx0 = _mm_sub_pd(d10, d00), dx1 = _mm_sub_pd(d11, d01);
  const __m128d lo = _mm_add_pd(d00, _mm_mul_pd(ax, dx0)), hi = _mm_add_pd(d01, _mm_mul_pd(ax, dx1));
  const __m128d hl = _mm_sub_pd(hi, lo);
  const __m128d d = _mm_add_pd(lo, _mm_mul_pd(ay, hl));
  const __m128d inv = _mm_div_pd(_mm_set1_pd(1.0), _mm_add_pd(c2, _mm_mul_pd(d, d)));
  const __m128d winv = _mm_mul_pd(w, inv);
  acc->inv = _mm_add_pd(acc->inv, winv);
  if constexpr (kGradient) {
    const __m128d gx = _mm_add_pd(dx0, _mm_mul_pd(ay, _mm_sub_pd(dx1, dx0))), gy = hl;
    const __m128d de = _mm_mul_pd(_mm_mul_pd(d, winv), inv);
    acc->gx = _mm_add_pd(acc->gx, _mm_mul_pd(de, gx));
    acc->gy = _mm_add_pd(acc->gy, _mm_mul_pd(de, gy));
    acc->gt = _mm_add_pd(acc->gt, _mm_mul_pd(de, _mm_sub_pd(_mm_mul_pd(gy, rx), _mm_mul_pd(gx, ry))));
  }
}

// Points k and k + 1.
template <bool kGradient>
[[gnu::always_inline]] inline void pair(const Setup& u, const Eigen::Vector2d* p, __m128d w, Lanes* acc, Terms* s) {
  const __m128d p0 = _mm_loadu_pd(p[0].data()), p1 = _mm_loadu_pd(p[1].data());
  const __m128d ox = _mm_unpacklo_pd(p0, p1), oy = _mm_unpackhi_pd(p0, p1);
  const __m128d va = _mm_set1_pd(u.a), vb = _mm_set1_pd(u.b);
  const __m128d rx = _mm_sub_pd(_mm_mul_pd(va, ox), _mm_mul_pd(vb, oy));
  const __m128d ry = _mm_add_pd(_mm_mul_pd(vb, ox), _mm_mul_pd(va, oy));
  const __m128d fx = _mm_add_pd(_mm_set1_pd(u.px), rx), fy = _mm_add_pd(_mm_set1_pd(u.py), ry);
  const __m128d zero = _mm_setzero_pd();
  const __m128d on = _mm_and_pd(_mm_and_pd(_mm_cmpge_pd(fx, zero), _mm_cmpge_pd(fy, zero)),
                                _mm_and_pd(_mm_cmplt_pd(fx, _mm_set1_pd(u.t.last_x)), _mm_cmplt_pd(fy, _mm_set1_pd(u.t.last_y))));
  if (_mm_movemask_pd(on) != 3) [[unlikely]] {
    alignas(16) double rxs[2], rys[2];
    _mm_store_pd(rxs, rx);
    _mm_store_pd(rys, ry);
    alignas(16) double ws[2];
    _mm_store_pd(ws, w);
    *s += point_terms<kGradient>(u, rxs[0], rys[0], ws[0]);
    *s += point_terms<kGradient>(u, rxs[1], rys[1], ws[1]);
    return;
  }
  const __m128i ix = _mm_cvttpd_epi32(fx), iy = _mm_cvttpd_epi32(fy);  // truncation = floor: fx, fy >= 0
  const std::ptrdiff_t nx = u.t.nx;
  const double* r0 = u.t.cells + _mm_cvtsi128_si32(iy) * nx + _mm_cvtsi128_si32(ix);
  const double* r1 = u.t.cells + _mm_cvtsi128_si32(_mm_shuffle_epi32(iy, 1)) * nx + _mm_cvtsi128_si32(_mm_shuffle_epi32(ix, 1));
  const __m128d top0 = _mm_loadu_pd(r0), bot0 = _mm_loadu_pd(r0 + nx), top1 = _mm_loadu_pd(r1), bot1 = _mm_loadu_pd(r1 + nx);
  lane_terms<kGradient>(_mm_set1_pd(u.c2), w, fx, fy, rx, ry, ix, iy, _mm_unpacklo_pd(top0, top1), _mm_unpackhi_pd(top0, top1),
                        _mm_unpacklo_pd(bot0, bot1), _mm_unpackhi_pd(bot0, bot1), acc);
}

template <bool kGradient>
[[gnu::always_inline]] inline double pairs(const Setup& u, const std::vector<Eigen::Vector2d>& pts, const double* w, double total, Eigen::Vector3d* grad) {
  const Eigen::Vector2d* p = pts.data();
  const std::size_t n = pts.size();
  Terms s;
  Lanes acc;
  std::size_t k = 0;
  const __m128d one = _mm_set1_pd(1.0);
  for (; k + 1 < n; k += 2) pair<kGradient>(u, p + k, w ? _mm_loadu_pd(w + k) : one, &acc, &s);
  acc.add_to(&s);
  for (; k < n; ++k) point<kGradient>(u, p[k], w ? w[k] : 1.0, &s);
  return finish(u, total, s, grad);
}

// The same loop twice: for any x86-64, and for AVX2 machines, whose three-operand (VEX) forms of
// the same SSE2 operations drop most register copies (matching workload -15 % instructions). No FMA
// either way (AVX2 alone does not enable it), so both give the same bits. Four AVX2 lanes with
// gathers were tried: 25 % fewer instructions again but no faster on this machine's CPU (BM_
// MatchingUpdate/200 25 vs 26 us CPU, interleaved), so not kept.
template <bool kGradient>
double data_term_sse2(const Setup u, const std::vector<Eigen::Vector2d>& pts, const double* w, double total, Eigen::Vector3d* grad) {
  return pairs<kGradient>(u, pts, w, total, grad);
}

template <bool kGradient>
__attribute__((target("avx2"))) double data_term_avx2(const Setup u, const std::vector<Eigen::Vector2d>& pts, const double* w, double total,
                                                           Eigen::Vector3d* grad) {
  return pairs<kGradient>(u, pts, w, total, grad);
}

// OMNILOC_NO_AVX2=1 takes the SSE2 loop on an AVX2 machine (ctest runs the regression and matching
// tests that way too, so both loops are shown to give the same bits).
bool has_avx2() {
  static const bool has = [] {
    const char* off = std::getenv("OMNILOC_NO_AVX2");
    if (off && *off && std::string(off) != "0") return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return has;
}
#endif

template <bool kGradient>
double data_term(const Setup& u, const std::vector<Eigen::Vector2d>& pts, const double* w, double total, Eigen::Vector3d* grad) {
#if defined(OMNILOC_X86)
  return has_avx2() ? data_term_avx2<kGradient>(u, pts, w, total, grad) : data_term_sse2<kGradient>(u, pts, w, total, grad);
#else
  Terms s;
  for (std::size_t k = 0; k < pts.size(); ++k) point<kGradient>(u, pts[k], w ? w[k] : 1.0, &s);
  return finish(u, total, s, grad);
#endif
}

}  // namespace

double match_data_term(const FieldMap& map, const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& q, double c, Eigen::Vector3d* grad,
                       const PointWeights* weights) {
  const FieldMap::Table& t = map.table();
  const Setup u{t, c * c, std::cos(q.z()) * t.inv_cell, std::sin(q.z()) * t.inv_cell, t.cells_x(q.x()), t.cells_y(q.y())};
  const double* w = weights && !weights->w.empty() ? weights->w.data() : nullptr;
  const double total = w ? weights->total : static_cast<double>(pts.size());
  return grad ? data_term<true>(u, pts, w, total, grad) : data_term<false>(u, pts, w, total, nullptr);
}

}  // namespace omniloc
