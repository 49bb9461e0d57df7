#include "harness/scoring/bound.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "core/angles.hpp"
#include "core/floor_tilt.hpp"

namespace omniloc::harness {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// 1.4826 x MAD is the standard deviation of a Gaussian sample, robust to up to half outliers.
constexpr double kMadToSigma = 1.4826;
// A band's sigma is never taken below 0.1 mm: a noiseless profile would otherwise give infinite
// information (the line points still carry the image's sub-pixel sampling, far above this).
constexpr double kSigmaFloor = 1e-4;
// A compass declared perfect still gets a finite (tiny) variance, so the matrices stay invertible.
constexpr double kCompassFloor = 1e-5;
// A tilt is fitted to a frame only from this many points or more (two unknowns; fewer points leave
// the fit's own noise larger than the vibration it is meant to measure).
constexpr std::size_t kMinTiltPoints = 8;
// A line point is the middle of the white run along its scan ray (localization/vision/scan_lines.cpp),
// so its error lies along the ray. A ray that meets the line at a grazing angle (the line's normal
// within 17.5 degrees of square to the ray, |n.u| < 0.3) runs over more than three line widths of
// white whose ends are the line's blurred edges smeared along the ray: its point is several times
// worse (on the tracking path 5-13 cm against 1.5-2.4 cm). Each range band has a sigma for the
// points it crosses and one for the grazing ones: kClasses = 2 x 5.
constexpr double kGrazing = 0.3;
constexpr std::size_t kBands = kBoundBands.size();
constexpr std::size_t kClasses = 2 * kBands;
// A class measured from fewer points takes its band's pooled figure.
constexpr std::size_t kMinClassPoints = 30;

// The k-th smallest of v's values (0-based) and, with `lower`, the (k-1)-th (k >= 1): the values
// nth_element finds, the same bytes (of a -0 and a +0 at the rank, either may come back, as from
// nth_element itself). On a large sample nth_element over the whole of it is
// mostly cache misses and mispredicted branches (the noise passes take medians of up to 150 000
// residuals), so a sample of kSelectSample values brackets the rank (4 sigma of the sample quantile
// either side), one branch-free pass keeps what lies in the bracket and counts what lies below, and
// nth_element finds the rank among the few kept (the medians of the 60 s tracking path's bound: 4.4 ms
// instead of 6.1). A bracket that misses the rank (a sample unlike the whole) falls back to
// nth_element over the whole. Reorders `v`.
constexpr std::size_t kSelectSample = 2048;
double select_rank(std::vector<double>& v, std::size_t k, double* lower) {
  const std::size_t n = v.size();
  if (n >= 4 * kSelectSample) {
    // One buffer per thread, grown when needed and kept between calls (fresh pages on every call
    // cost more than the pass): the values kept first, the sample behind them.
    thread_local std::vector<double> buf;
    if (buf.size() < n + kSelectSample) buf.resize(n + kSelectSample);
    const auto kept = buf.begin();
    const auto sample = buf.begin() + static_cast<std::ptrdiff_t>(n);
    const std::size_t stride = n / kSelectSample;
    for (std::size_t i = 0; i < kSelectSample; ++i) sample[static_cast<std::ptrdiff_t>(i)] = v[i * stride];
    const double s = static_cast<double>(kSelectSample);
    const double q = (static_cast<double>(k) + 0.5) / static_cast<double>(n) * s;
    const double d = 4.0 * std::sqrt(0.25 * s) + 1.0;
    const auto il = static_cast<std::ptrdiff_t>(std::max(0.0, std::floor(q - d)));
    const auto ih = static_cast<std::ptrdiff_t>(std::min(s - 1.0, std::ceil(q + d)));
    std::nth_element(sample, sample + ih, sample + static_cast<std::ptrdiff_t>(kSelectSample));
    const double hi = sample[ih];
    std::nth_element(sample, sample + il, sample + ih);
    const double lo = sample[il];
    std::size_t below = 0, m = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = v[i];
      below += x < lo ? 1 : 0;
      kept[static_cast<std::ptrdiff_t>(m)] = x;
      m += (x >= lo && x <= hi) ? 1 : 0;
    }
    if ((lower ? k - 1 : k) >= below && k < below + m) {
      const auto r = static_cast<std::ptrdiff_t>(k - below);
      std::nth_element(kept, kept + r, kept + static_cast<std::ptrdiff_t>(m));
      if (lower) *lower = *std::max_element(kept, kept + r);
      return kept[r];
    }
  }
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  if (lower) *lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k));
  return v[k];
}

// Reorders `v`: the value does not depend on the order it finds.
double median_in_place(std::vector<double>& v) {
  if (v.empty()) return std::nan("");
  const std::size_t n = v.size() / 2;
  if (v.size() % 2) return select_rank(v, n, nullptr);
  double lo = 0.0;
  const double hi = select_rank(v, n, &lo);
  return 0.5 * (hi + lo);
}

// By value: callers that no longer need their sample move it in.
double median(std::vector<double> v) { return median_in_place(v); }

// 1.4826 x the median absolute deviation from the median; NaN for an empty sample.
double robust_sigma(std::vector<double> v, double* centre = nullptr) {
  if (centre) *centre = std::nan("");
  if (v.empty()) return std::nan("");
  // The deviations are taken in the order the first median left: the same values, so the same median.
  const double m = median_in_place(v);
  if (centre) *centre = m;
  for (double& x : v) x = std::fabs(x - m);
  return kMadToSigma * median_in_place(v);
}

int band_of(double r) {
  int b = 0;
  for (std::size_t i = 1; i < kBoundBands.size(); ++i)
    if (r >= kBoundBands[i]) b = static_cast<int>(i);
  return b;
}


Json num_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// Nearest point of a segment: the signed distance along its normal inside, the distance to the end
// (along the direction to it) beyond an end.
void consider_segment(const Eigen::Vector2d& w, const Eigen::Vector2d& a, const Eigen::Vector2d& b, int index, double& best, MarkingMatch& m) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0)) return;
  const double u = (w - a).dot(ab) / len2;
  const Eigen::Vector2d q = a + std::clamp(u, 0.0, 1.0) * ab;
  const double d = (w - q).norm();
  if (!(d < best)) return;
  best = d;
  const Eigen::Vector2d n0 = Eigen::Vector2d(-ab.y(), ab.x()) / std::sqrt(len2);
  m.kind = 1;
  m.marking = index;
  if ((u > 0 && u < 1) || d < 1e-9) {
    m.normal = n0;
    m.residual = n0.dot(w - a);
  } else {
    m.normal = (w - q) / d;
    m.residual = d;
  }
}

// An arc's start and end directions and end points: the same for every point matched against it.
struct ArcEnds {
  Eigen::Vector2d e0, e1;
  std::array<Eigen::Vector2d, 2> ends;
  explicit ArcEnds(const ArcMarking& arc)
      : e0(std::cos(arc.start), std::sin(arc.start)),
        e1(std::cos(arc.start + arc.sweep), std::sin(arc.start + arc.sweep)),
        ends{arc.centre + arc.radius * e0, arc.centre + arc.radius * e1} {}
};

void consider_arc(const Eigen::Vector2d& w, const ArcMarking& arc, const ArcEnds& ae, int index, double& best, MarkingMatch& m) {
  const Eigen::Vector2d dc = w - arc.centre;
  const double r = dc.norm();
  if (!(r > 1e-9)) return;
  bool inside = arc.sweep >= kTwoPi - 1e-12;
  if (!inside && arc.sweep <= kPi) {
    // Within the sweep: anticlockwise of its start direction and clockwise of its end (no atan2).
    const Eigen::Vector2d& e0 = ae.e0;
    const Eigen::Vector2d& e1 = ae.e1;
    inside = e0.x() * dc.y() - e0.y() * dc.x() >= 0 && dc.x() * e1.y() - dc.y() * e1.x() >= 0;
  } else if (!inside) {
    inside = wrap_angle_positive(std::atan2(dc.y(), dc.x()) - arc.start) <= arc.sweep;
  }
  if (inside) {
    const double d = std::fabs(r - arc.radius);
    if (!(d < best)) return;
    best = d;
    m.kind = 1;
    m.marking = index;
    m.normal = dc / r;
    m.residual = r - arc.radius;
    return;
  }
  for (const Eigen::Vector2d& e : ae.ends) {
    const double d = (w - e).norm();
    if (!(d < best)) continue;
    best = d;
    m.kind = 1;
    m.marking = index;
    m.normal = d > 1e-9 ? Eigen::Vector2d((w - e) / d) : Eigen::Vector2d(dc / r);
    m.residual = d;
  }
}

// A painted spot is a disc: a point on it has no normal, so it measures nothing the bound can use.
void consider_spot(const Eigen::Vector2d& w, const SpotMarking& s, double& best, MarkingMatch& m) {
  const double d = std::max(0.0, (w - s.centre).norm() - s.radius);
  if (d < best) {
    best = d;
    m.kind = 2;
    m.marking = -1;
    m.residual = d;
  }
}

}  // namespace

MarkingMatch match_marking(const Field& field, const Eigen::Vector2d& w) {
  MarkingMatch m;
  double best = kInf;
  int index = 0;
  for (const auto& s : field.segments) consider_segment(w, s.a, s.b, index++, best, m);
  for (const auto& a : field.arcs) consider_arc(w, a, ArcEnds(a), index++, best, m);
  for (const auto& s : field.spots) consider_spot(w, s, best, m);
  return m;
}

Eigen::Matrix3d frame_information(const std::vector<BoundRow>& rows, const Eigen::Matrix2d& tilt_cov, double line_corr, Eigen::Vector3d* score) {
  // J = H^T R^-1 H with R = D + A C A^T; Woodbury: R^-1 = D^-1 - D^-1 A (C^-1 + A^T D^-1 A)^-1 A^T D^-1.
  // The nuisances: the tilt (2) and, with line_corr > 0, one offset per marking.
  // At most kMaxLines markings get an offset of their own (a frame sees about ten); the points of
  // any further one are taken as independent. Bounded sizes keep the matrices off the heap.
  constexpr int kMaxLines = 30;
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 2 + kMaxLines, 2 + kMaxLines>;
  using Row3 = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 2 + kMaxLines>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 2 + kMaxLines, 1>;
  int lines = 0;
  if (line_corr > 0)
    for (const auto& r : rows) lines = std::max(lines, std::min(r.line + 1, kMaxLines));
  const int m = 2 + lines;
  Eigen::Matrix3d HDH = Eigen::Matrix3d::Zero();
  Row3 HDA = Row3::Zero(3, m);
  Mat ADA = Mat::Zero(m, m);
  Eigen::Vector3d HDe = Eigen::Vector3d::Zero();
  Vec ADe = Vec::Zero(m);
  for (const auto& r : rows) {
    const double w = 1.0 / r.var;
    HDH.noalias() += w * r.h * r.h.transpose();
    HDA.leftCols<2>().noalias() += w * r.h * r.a.transpose();
    ADA.topLeftCorner<2, 2>().noalias() += w * r.a * r.a.transpose();
    if (score) {
      HDe += w * r.e * r.h;
      ADe.head<2>() += w * r.e * r.a;
    }
    if (lines > 0 && r.line >= 0 && r.line < kMaxLines) {
      const int c = 2 + r.line;
      HDA.col(c) += w * r.load * r.h;
      ADA(c, c) += w * r.load * r.load;
      ADA.block(0, c, 2, 1) += w * r.load * r.a;
      ADA.block(c, 0, 1, 2) += w * r.load * r.a.transpose();
      if (score) ADe(c) += w * r.load * r.e;
    }
  }
  Mat C = Mat::Zero(m, m);
  C.topLeftCorner<2, 2>() = tilt_cov;
  for (int c = 2; c < m; ++c) C(c, c) = line_corr;
  if (C.isZero(0.0)) {
    if (score) *score = HDe;
    return HDH;
  }
  // (C^-1 + ADA)^-1 = C (I + ADA C)^-1: defined also for a singular C (one axis without vibration).
  const Mat S = C * Mat(Mat::Identity(m, m) + ADA * C).partialPivLu().inverse();
  if (score) *score = HDe - HDA * (S * ADe);
  Eigen::Matrix3d J = HDH - HDA * S * HDA.transpose();
  return 0.5 * (J + J.transpose());
}

CovarianceBound invert_information(const Eigen::Matrix3d& info) {
  CovarianceBound b;
  // Scaled to unit diagonal, so that metres and radians weigh alike in the conditioning test.
  Eigen::Vector3d s;
  for (int i = 0; i < 3; ++i) {
    if (!(info(i, i) > 0) || !std::isfinite(info(i, i))) {
      b.why = "ill-conditioned";
      return b;
    }
    s(i) = 1.0 / std::sqrt(info(i, i));
  }
  const Eigen::Matrix3d n = s.asDiagonal() * info * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(n, Eigen::EigenvaluesOnly);
  // 1e-9: a direction known a billion times worse than the best one (in variance) is not known.
  if (!(es.eigenvalues()(0) > 1e-9 * es.eigenvalues()(2))) {
    b.why = "ill-conditioned";
    return b;
  }
  b.cov = s.asDiagonal() * n.inverse() * s.asDiagonal();
  b.cov = 0.5 * (b.cov + b.cov.transpose());
  b.finite = true;
  return b;
}

namespace {
template <class M>
M posterior_step_impl(const M& P, const M& F, const M& Q, const M& Jz) {
  const M Pp = F * P * F.transpose() + Q;
  // (I + Pp Jz) is invertible for positive semi-definite Pp and Jz (its eigenvalues are 1 + those of
  // Pp^1/2 Jz Pp^1/2 >= 1).
  const M I = M::Identity(Pp.rows(), Pp.cols());
  const M out = M(I + Pp * Jz).partialPivLu().solve(Pp);
  return 0.5 * (out + out.transpose());
}
}  // namespace

Eigen::MatrixXd posterior_step(const Eigen::MatrixXd& P, const Eigen::MatrixXd& F, const Eigen::MatrixXd& Q, const Eigen::MatrixXd& Jz) {
  return posterior_step_impl<Eigen::MatrixXd>(P, F, Q, Jz);
}

namespace {
// One step of the check's filter in error form (P- and e- already predicted): the update with the
// frame's information J and score, the same arithmetic as posterior_step_impl's.
template <class M, class V>
void oracle_update(V& e, M& P, const M& J, const V& score) {
  const M I = M::Identity(P.rows(), P.cols());
  const auto lu = M(I + P * J).partialPivLu();
  e = lu.solve(V(e - P * score));
  const M out = lu.solve(P);
  P = 0.5 * (out + out.transpose());
}

template <class M, class V>
void oracle_tally(const V& e, const M& P, double settle_pos_var, OracleResult& r) {
  if (P(0, 0) + P(1, 1) > settle_pos_var) return;
  r.pos_sq += e(0) * e(0) + e(1) * e(1);
  r.heading_sq += e(2) * e(2);
  r.pos_var += P(0, 0) + P(1, 1);
  r.heading_var += P(2, 2);
  ++r.frames;
}
}  // namespace

OracleResult posterior_oracle(const std::vector<OracleStep>& steps, const Eigen::VectorXd& e0, const Eigen::MatrixXd& P0, double settle_pos_var) {
  OracleResult r;
  Eigen::VectorXd e = e0;
  Eigen::MatrixXd P = P0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const OracleStep& s = steps[k];
    if (s.reset) {
      P = s.reset_cov;
    } else if (k > 0) {
      e = s.F * e + s.process_error;
      P = s.F * P * s.F.transpose() + s.Q;
    }
    oracle_update(e, P, s.info, s.score);
    oracle_tally(e, P, settle_pos_var, r);
  }
  return r;
}

namespace {
// J = V diag(w) V^T: its symmetric root, the root's inverse on the range and the projector on the
// range. A direction with less than 1e-12 of the largest eigenvalue is outside the range (the
// information along a line is that many orders below across it).
struct InfoRoots {
  Eigen::Matrix3d root = Eigen::Matrix3d::Zero(), inv_root = Eigen::Matrix3d::Zero(), proj = Eigen::Matrix3d::Zero();
};
InfoRoots info_roots(const Eigen::Matrix3d& J) {
  InfoRoots r;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(0.5 * (J + J.transpose()));
  const Eigen::Vector3d w = es.eigenvalues();
  const double top = w.maxCoeff();
  if (!(top > 0)) return r;
  const Eigen::Matrix3d& V = es.eigenvectors();
  Eigen::Vector3d sq = Eigen::Vector3d::Zero(), isq = Eigen::Vector3d::Zero(), on = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (w(i) > 1e-12 * top) {
      sq(i) = std::sqrt(w(i));
      isq(i) = 1.0 / sq(i);
      on(i) = 1.0;
    }
  }
  r.root = V * sq.asDiagonal() * V.transpose();
  r.inv_root = V * isq.asDiagonal() * V.transpose();
  r.proj = V * on.asDiagonal() * V.transpose();
  return r;
}

// The frame's whitened error J^{1/2} e from its score, e = -J^+ score (whitened_error's formula, for
// roots already made).
Eigen::Vector3d whitened(const InfoRoots& r, const Eigen::Vector3d& score) { return -(r.inv_root * score); }

// The frame's rows H = [J^{1/2}, 0, sqrt(rho) Pi] on a state of N entries (pose first, z last); the
// fresh part's covariance is (1 - rho) I.
template <int N>
Eigen::Matrix<double, 3, N> correlated_rows(const InfoRoots& r, double rho, int n = N) {
  Eigen::Matrix<double, 3, N> H = Eigen::Matrix<double, 3, N>::Zero(3, n);
  H.template leftCols<3>() = r.root;
  H.template rightCols<3>() = std::sqrt(rho) * r.proj;
  return H;
}

// One update of the temporal model with a frame: rows H (pose and z), fresh noise (1 - rho) I
// (invertible: rho <= kMaxCarriedShare). In Kalman form, P - (H P)^T S^-1 (H P) with the 3 x 3
// innovation covariance S: the information form's (I + P Jz)^-1 P with Jz = H^T H / (1 - rho), at a
// fraction of the cost of a solve over the whole state. `x` is the check's filter state (pose and
// scale errors first, the estimate of z last) and `eta` the frame's whitened error, so that the
// innovation is eta - H x; the bound's recursion, which has no state, passes zeros.
template <class M, class V, class H3>
void correlated_update(M& P, V& x, const H3& H, double rho, const Eigen::Vector3d& eta) {
  const auto HP = (H * P).eval();
  const Eigen::Matrix3d S = HP * H.transpose() + (1.0 - rho) * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Si = S.inverse();
  x += HP.transpose() * (Si * (eta - H * x));
  const M out = P - HP.transpose() * (Si * HP);
  P = 0.5 * (out + out.transpose());
}

// The motion of the augmented state: the steps' F, Q on the first n entries; z times a, with
// (1 - a^2) noise so that its variance stays 1. P <- Fa P Fa^T + Qa by blocks (Fa is block diagonal).
template <class M, class MF>
void predict_augmented(M& P, const MF& F, const MF& Q, double a) {
  const Eigen::Index n = F.rows();
  const MF Pnn = P.topLeftCorner(n, n);
  P.topLeftCorner(n, n) = F * Pnn * F.transpose() + Q;
  const auto Pnz = (a * (F * P.topRightCorner(n, 3))).eval();
  P.topRightCorner(n, 3) = Pnz;
  P.bottomLeftCorner(3, n) = Pnz.transpose();
  P.bottomRightCorner(3, 3) = a * a * P.bottomRightCorner(3, 3) + (1.0 - a * a) * Eigen::Matrix3d::Identity();
}
}  // namespace

Eigen::Vector3d whitened_error(const Eigen::Matrix3d& info, const Eigen::Vector3d& score) { return whitened(info_roots(info), score); }

TemporalCorrelation fit_temporal_correlation(const std::vector<Eigen::Vector3d>& eta, const std::vector<bool>& has,
                                             const std::vector<int>& segment, int max_lag) {
  TemporalCorrelation tc;
  tc.lags = std::max(1, max_lag);
  const std::size_t n = eta.size();
  double r0 = 0;
  std::size_t n0 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (!has[k]) continue;
    r0 += eta[k].squaredNorm();
    ++n0;
  }
  std::vector<double> r(static_cast<std::size_t>(tc.lags), std::numeric_limits<double>::quiet_NaN());
  for (int l = 1; l <= tc.lags; ++l) {
    double sum = 0;
    std::size_t pairs = 0;
    for (std::size_t k = 0; k + static_cast<std::size_t>(l) < n; ++k) {
      const std::size_t j = k + static_cast<std::size_t>(l);
      if (!has[k] || !has[j] || segment[k] != segment[j]) continue;
      sum += eta[k].dot(eta[j]);
      ++pairs;
    }
    if (l == 1) tc.pairs = pairs;
    if (pairs > 0 && r0 > 0) r[static_cast<std::size_t>(l - 1)] = (sum / static_cast<double>(pairs)) / (r0 / static_cast<double>(n0));
  }
  tc.autocorrelation = r;
  if (tc.pairs < 3 * static_cast<std::size_t>(tc.lags)) {
    tc.why = "fewer than " + std::to_string(3 * tc.lags) + " pairs of consecutive frames with a bound: taken as independent";
    return tc;
  }
  // rho a^l against r(l): for each a, the least-squares rho is sum r a^l / sum a^2l.
  double best = std::numeric_limits<double>::infinity();
  for (int i = 1; i < 1000; ++i) {
    const double a = 0.001 * i;
    double ra = 0, aa = 0;
    double p = 1;
    for (int l = 1; l <= tc.lags; ++l) {
      p *= a;
      const double rl = r[static_cast<std::size_t>(l - 1)];
      if (!std::isfinite(rl)) continue;
      ra += rl * p;
      aa += p * p;
    }
    if (!(aa > 0)) continue;
    const double rho = std::clamp(ra / aa, 0.0, kMaxCarriedShare);
    double sse = 0;
    p = 1;
    for (int l = 1; l <= tc.lags; ++l) {
      p *= a;
      const double rl = r[static_cast<std::size_t>(l - 1)];
      if (std::isfinite(rl)) sse += (rl - rho * p) * (rl - rho * p);
    }
    if (sse < best) {
      best = sse;
      tc.rho = rho;
      tc.a = a;
    }
  }
  if (tc.rho <= 0) tc.a = 0;
  return tc;
}

Eigen::MatrixXd correlated_frame_information(const Eigen::Matrix3d& info, double rho, int states) {
  using HX = Eigen::Matrix<double, 3, Eigen::Dynamic>;
  const HX H = correlated_rows<Eigen::Dynamic>(info_roots(info), rho, states);
  return H.transpose() * H / (1.0 - rho);
}

OracleResult posterior_oracle_correlated(const std::vector<OracleStep>& steps, const std::vector<Eigen::Vector3d>& eta,
                                         const TemporalCorrelation& tc, const Eigen::VectorXd& e0, const Eigen::MatrixXd& P0,
                                         double settle_pos_var, OracleResult* white) {
  using MX = Eigen::MatrixXd;
  using VX = Eigen::VectorXd;
  OracleResult r;
  const Eigen::Index n = e0.size(), N = n + 3;
  VX x = VX::Zero(N);
  x.head(n) = e0;
  MX P = MX::Zero(N, N);
  P.topLeftCorner(n, n) = P0;
  P.bottomRightCorner(3, 3).setIdentity();
  VX ew = e0;
  MX Pw = P0;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const OracleStep& s = steps[k];
    if (s.reset) {
      P.topLeftCorner(n, n) = s.reset_cov;
      P.block(0, n, 3, 3).setZero();
      P.block(n, 0, 3, 3).setZero();
      Pw = s.reset_cov;
    } else if (k > 0) {
      x.head(n) = s.F * x.head(n) + s.process_error;
      x.tail<3>() *= tc.a;
      predict_augmented(P, s.F, s.Q, tc.a);
      ew = s.F * ew + s.process_error;
      Pw = s.F * Pw * s.F.transpose() + s.Q;
    }
    const InfoRoots ir = info_roots(s.info.topLeftCorner<3, 3>());
    if (ir.proj.any()) correlated_update(P, x, correlated_rows<Eigen::Dynamic>(ir, tc.rho, static_cast<int>(N)), tc.rho, eta[k]);
    oracle_tally(x, P, settle_pos_var, r);
    if (white) {
      oracle_update(ew, Pw, s.info, s.score);
      oracle_tally(ew, P, settle_pos_var, *white);
    }
  }
  return r;
}

BoundRow bound_row(const MarkingMatch& m, const Eigen::Vector2d& world, const Pose2& pose, const Eigen::Vector2d& robot, double var, double h) {
  BoundRow row;
  const Eigen::Vector2d d = world - pose.translation();
  row.h = Eigen::Vector3d(m.normal.x(), m.normal.y(), d.x() * m.normal.y() - d.y() * m.normal.x());
  row.var = var;
  row.a = floor_tilt_jacobian(robot, h).transpose() * (pose.rotation().transpose() * m.normal);
  row.e = m.residual;
  return row;
}

namespace {

// Whether a move without odometry (teleport, kidnap) at time `tm` falls between the frames at `ta`
// and `tb`: the simulation applies an event at the first physics step at or after its time, so an
// event at a frame's own time moves the robot after that frame.
bool moved_between(double tm, double ta, double tb) { return tm >= ta - 1e-9 && tm < tb - 1e-9; }

// Per frame: whether a move without odometry fell between it and the previous frame (the posterior
// starts again there, and no odometry increment spans it).
std::vector<bool> resets_before(const std::vector<FrameRecord>& frames, const std::vector<double>& resets) {
  std::vector<bool> out(frames.size(), false);
  for (std::size_t k = 1; k < frames.size(); ++k)
    for (double tr : resets) out[k] = out[k] || moved_between(tr, frames[k - 1].t, frames[k].t);
  return out;
}

// A frame's line point matched at the exposure pose.
// Kept small (64 bytes): the noise passes stream through every point of the run several times.
struct PointRes {
  double residual = 0.0;
  Eigen::Vector3d h = Eigen::Vector3d::Zero();  // d(residual)/d(x, y, theta): (normal, lever)
  Eigen::Vector2d a = Eigen::Vector2d::Zero();  // d(residual)/d(tilt)
  float offset = 0.0f;  // normal . world point: which of parallel lines it lies on
  std::int16_t marking = -1;
  std::uint8_t band = 0;  // range band and incidence class
  bool near = false;      // within the wide first gate
  bool inlier = false;    // and within its frame's gate once the tilt is out
};

struct FrameWork {
  Pose2 pose;  // the pose the image was exposed at
  std::vector<PointRes> pts;
  std::size_t raw_points = 0, spot_points = 0, far_points = 0;
  bool tilt_fitted = false;
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  Eigen::Matrix2d tilt_var = Eigen::Matrix2d::Zero();
};

// d(residual)/d(tilt) of a point, computed once when it is matched (bound_row's a).
const Eigen::Vector2d& tilt_row(const PointRes& q, const Pose2&, double) { return q.a; }

// The pose each frame's image was exposed at: the truth `latency` before the frame, on the
// simulation's step grid as the renderer picks it (harness/simulation.cpp camera_view),
// interpolated between the recorded frames (never across a kidnap).
std::vector<Pose2> exposure_poses(const RobotRecord& robot, const BoundSetup& setup) {
  const auto& f = robot.frames;
  std::vector<Pose2> out(f.size());
  for (std::size_t k = 0; k < f.size(); ++k) {
    out[k] = f[k].truth;
    if (!(setup.latency_s > 0)) continue;
    const double te = std::floor((f[k].t - setup.latency_s + 1e-9) / setup.physics_dt) * setup.physics_dt;
    if (te < 0 || k == 0) continue;  // before the first step the camera shows the present
    std::size_t j = k;
    while (j > 0 && f[j].t > te + 1e-12) --j;
    if (f[j].t > te + 1e-12) continue;
    const std::size_t j1 = std::min(j + 1, k);
    std::optional<double> moved;
    for (double tr : setup.resets)
      if (moved_between(tr, f[j].t, f[j1].t)) moved = tr;
    if (j1 == j || moved) {
      // Across a move without odometry: the pose on the side of it the exposure lies.
      out[k] = moved && te > *moved + 1e-9 ? f[j1].truth : f[j].truth;
      continue;
    }
    const double u = (te - f[j].t) / (f[j1].t - f[j].t);
    const Pose2& a = f[j].truth;
    const Pose2& b = f[j1].truth;
    out[k] = Pose2(a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * angle_diff(b.theta, a.theta));
  }
  return out;
}

// Fits each frame's tilt to its inliers' residuals (weights from `sigma`): generalized least
// squares, its own variance beside it.
void fit_tilts(std::vector<FrameWork>& work, const std::array<double, kClasses>& sigma, double h) {
  for (auto& fw : work) {
    fw.tilt_fitted = false;
    Eigen::Matrix2d N = Eigen::Matrix2d::Zero();
    Eigen::Vector2d b = Eigen::Vector2d::Zero();
    std::size_t n = 0;
    for (const auto& q : fw.pts) {
      if (!q.inlier) continue;
      const Eigen::Vector2d a = tilt_row(q, fw.pose, h);
      const double w = 1.0 / (sigma[static_cast<std::size_t>(q.band)] * sigma[static_cast<std::size_t>(q.band)]);
      N.noalias() += w * a * a.transpose();
      b += w * a * q.residual;
      ++n;
    }
    if (n < kMinTiltPoints) continue;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(N, Eigen::EigenvaluesOnly);
    if (!(es.eigenvalues()(0) > 1e-6 * es.eigenvalues()(1))) continue;  // points in one direction only
    fw.tilt_var = N.inverse();
    fw.tilt = fw.tilt_var * b;
    fw.tilt_fitted = true;
  }
}

// Each band's white sigma from the residuals less the frame's fitted tilt, each divided by
// sqrt(1 - leverage) so that the two fitted unknowns do not shrink it.
std::array<double, kClasses> white_sigmas(const std::vector<FrameWork>& work, const std::array<double, kClasses>& weights_sigma, double h,
                                   std::array<std::size_t, kClasses>* counts, std::array<double, kClasses>* medians) {
  std::array<std::vector<double>, kClasses> res;
  for (const auto& fw : work) {
    if (!fw.tilt_fitted) continue;
    for (const auto& q : fw.pts) {
      if (!q.inlier) continue;
      const Eigen::Vector2d a = tilt_row(q, fw.pose, h);
      const double s = weights_sigma[static_cast<std::size_t>(q.band)];
      const double lev = std::clamp(a.dot(fw.tilt_var * a) / (s * s), 0.0, 0.9);
      res[static_cast<std::size_t>(q.band)].push_back((q.residual - a.dot(fw.tilt)) / std::sqrt(1.0 - lev));
    }
  }
  std::array<double, kClasses> out;
  for (std::size_t b = 0; b < kClasses; ++b) {
    if (counts) (*counts)[b] = res[b].size();
    double m = 0;
    out[b] = robust_sigma(std::move(res[b]), &m);
    if (medians) (*medians)[b] = m;
  }
  return out;
}

// The correlation of two points' errors on one marking in one frame, by moments: for a marking's
// n points with standardized errors z, Var(sum z) = n (1 + (n - 1) rho). The class medians (biases,
// not in the bound) are taken out first.
double line_correlation(const std::vector<FrameWork>& work, const std::array<double, kClasses>& sigma, const std::array<double, kClasses>& medians,
                        double h) {
  double num = 0, den = 0;
  std::vector<std::pair<double, int>> groups;  // by marking index
  for (const auto& fw : work) {
    if (!fw.tilt_fitted) continue;
    groups.clear();
    for (const auto& q : fw.pts) {
      if (!q.inlier) continue;
      const std::size_t c = static_cast<std::size_t>(q.band);
      const Eigen::Vector2d a = tilt_row(q, fw.pose, h);
      const double lev = std::clamp(a.dot(fw.tilt_var * a) / (sigma[c] * sigma[c]), 0.0, 0.9);
      const double med = std::isfinite(medians[c]) ? medians[c] : 0.0;
      if (static_cast<std::size_t>(q.marking) >= groups.size()) groups.resize(static_cast<std::size_t>(q.marking) + 1, {0.0, 0});
      auto& g = groups[static_cast<std::size_t>(q.marking)];
      g.first += ((q.residual - a.dot(fw.tilt)) / std::sqrt(1.0 - lev) - med) / sigma[c];
      ++g.second;
    }
    for (const auto& g : groups) {
      const double n = g.second;
      num += g.first * g.first - n;
      den += n * (n - 1);
    }
  }
  return den > 0 ? std::clamp(num / den, 0.0, 0.95) : 0.0;
}

// Why a frame's information has no inverse: a name a reader can act on.
std::string singular_reason(const FrameWork& fw) {
  const PointRes* first = nullptr;
  bool parallel = true, collinear = true;
  for (const auto& q : fw.pts) {
    if (!q.inlier) continue;
    if (!first) {
      first = &q;
      continue;
    }
    const double c = first->h.x() * q.h.y() - first->h.y() * q.h.x(), d = first->h.x() * q.h.x() + first->h.y() * q.h.y();
    parallel = parallel && std::fabs(c) < 1e-6;
    collinear = collinear && std::fabs((d < 0 ? -q.offset : q.offset) - first->offset) < 0.05f;
  }
  if (first && parallel) return collinear ? "points on one line" : "points on parallel lines";
  return "ill-conditioned";
}

struct Series {
  std::vector<double> pos, heading;
};

Json series_json(const Series& s, std::size_t scored) {
  const auto rms = [](const std::vector<double>& v) {
    if (v.empty()) return Json(nullptr);
    double a = 0;
    for (double x : v) a += x * x;
    return Json(std::sqrt(a / static_cast<double>(v.size())));
  };
  return Json{{"position_rms_m", rms(s.pos)},
              {"heading_rms_rad", rms(s.heading)},
              {"position_median_m", s.pos.empty() ? Json(nullptr) : Json(median(s.pos))},
              {"frames", s.pos.size()},
              {"share", scored ? Json(static_cast<double>(s.pos.size()) / static_cast<double>(scored)) : Json(nullptr)}};
}

}  // namespace

Json efficiency_json(const RobotRecord& robot, const std::vector<std::optional<double>>& pos_bound,
                     const std::vector<std::optional<double>>& heading_bound, const std::string& against, const std::vector<Pose2>* exposure,
                     const std::vector<std::pair<double, double>>* excluded) {
  double se = 0, sb = 0, sth = 0, sbth = 0, sx = 0;
  std::size_t n = 0, scored = 0;
  for (std::size_t k = 0; k < robot.frames.size(); ++k) {
    const FrameRecord& r = robot.frames[k];
    bool out = false;
    if (excluded)
      for (const auto& [a, b] : *excluded) out = out || (r.t >= a && r.t < b);
    if (out) continue;
    ++scored;
    if (!r.valid || !pos_bound[k] || !heading_bound[k]) continue;
    const double ex = r.est.x - r.truth.x, ey = r.est.y - r.truth.y, eth = angle_diff(r.est.theta, r.truth.theta);
    se += ex * ex + ey * ey;
    sth += eth * eth;
    sb += *pos_bound[k] * *pos_bound[k];
    sbth += *heading_bound[k] * *heading_bound[k];
    if (exposure) sx += std::pow(r.est.x - (*exposure)[k].x, 2) + std::pow(r.est.y - (*exposure)[k].y, 2);
    ++n;
  }
  Json j{{"against", against}, {"frames", n}, {"share", scored ? Json(static_cast<double>(n) / static_cast<double>(scored)) : Json(nullptr)}};
  if (n == 0) {
    j["position"] = nullptr;
    j["heading"] = nullptr;
    j["why_null"] = "no frame has both an estimate and a finite bound";
    return j;
  }
  const double N = static_cast<double>(n);
  j["rmse_m"] = std::sqrt(se / N);
  j["bound_rms_m"] = std::sqrt(sb / N);
  j["heading_rmse_rad"] = std::sqrt(sth / N);
  j["heading_bound_rms_rad"] = std::sqrt(sbth / N);
  // The same estimates against the pose the images were exposed at: how much of the error is the
  // camera's latency (a localizer that does not carry its estimate forward over it).
  if (exposure) j["rmse_at_exposure_m"] = std::sqrt(sx / N);
  // A bound of exactly 0 (a pose given and never disturbed) makes every error infinitely inefficient.
  j["position"] = sb > 0 ? Json(std::sqrt(se / sb)) : Json(nullptr);
  j["heading"] = sbth > 0 ? Json(std::sqrt(sth / sbth)) : Json(nullptr);
  if (!(sb > 0) || !(sbth > 0)) j["why_null"] = "the bound is 0 over these frames (the pose was known exactly)";
  return j;
}

namespace {

// The markings that can be the nearest to some point of each 0.5 m cell of the floor, so that a
// point is compared with those instead of all of them (the match is a quarter of the bound's cost).
class MarkingIndex {
 public:
  explicit MarkingIndex(const Field& f) : f_(f) {
    for (const auto& a : f.arcs) arc_ends_.emplace_back(a);
    x0_ = -f.half_floor_x() - kMatchReach;
    y0_ = -f.half_floor_y() - kMatchReach;
    nx_ = static_cast<int>(std::ceil(2 * (f.half_floor_x() + kMatchReach) / kCell));
    ny_ = static_cast<int>(std::ceil(2 * (f.half_floor_y() + kMatchReach) / kCell));
    cells_.resize(static_cast<std::size_t>(nx_ * ny_));
    const double half = kCell * std::sqrt(0.5);  // from the cell's centre to its corners
    const double reach = kMatchReach + half;       // any point of the cell
    std::vector<double> ds(f.segments.size()), da(f.arcs.size()), dp(f.spots.size());
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        const Eigen::Vector2d c(x0_ + (i + 0.5) * kCell, y0_ + (j + 0.5) * kCell);
        // A marking is left out of the cell when another one is nearer to every point of it: its
        // distance from the centre less `half` (the nearest any point of the cell can be to it)
        // beyond the other's plus `half` (the farthest). A point's match is then the one it had
        // with every marking compared: its nearest, the first of equals. Markings that
        // consider_* may pass over (a segment of no length, an arc at its own centre) never
        // stand in for another.
        double nearest = kInf;
        for (std::size_t k = 0; k < f.segments.size(); ++k) {
          ds[k] = distance_to_segment(c, f.segments[k].a, f.segments[k].b);
          if ((f.segments[k].b - f.segments[k].a).squaredNorm() > 0) nearest = std::min(nearest, ds[k] + half);
        }
        for (std::size_t k = 0; k < f.arcs.size(); ++k) {
          da[k] = distance_to_arc(c, f.arcs[k]);
          if ((c - f.arcs[k].centre).norm() > half + kPruneMargin) nearest = std::min(nearest, da[k] + half);
        }
        for (std::size_t k = 0; k < f.spots.size(); ++k) {
          dp[k] = std::max(0.0, (c - f.spots[k].centre).norm() - f.spots[k].radius);
          nearest = std::min(nearest, dp[k] + half);
        }
        const auto keep = [&](double d) { return d <= reach && d - half <= nearest + kPruneMargin; };
        auto& cell = cells_[static_cast<std::size_t>(j * nx_ + i)];
        for (std::size_t k = 0; k < f.segments.size(); ++k)
          if (keep(ds[k])) cell.segments.push_back(static_cast<int>(k));
        for (std::size_t k = 0; k < f.arcs.size(); ++k)
          if (keep(da[k])) cell.arcs.push_back(static_cast<int>(k));
        for (std::size_t k = 0; k < f.spots.size(); ++k)
          if (keep(dp[k])) cell.spots.push_back(static_cast<int>(k));
      }
  }
  /// As match_marking, for points within kMatchReach of a marking (kind 0 beyond).
  MarkingMatch match(const Eigen::Vector2d& w) const {
    MarkingMatch m;
    const int i = static_cast<int>(std::floor((w.x() - x0_) / kCell)), j = static_cast<int>(std::floor((w.y() - y0_) / kCell));
    if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return m;
    const Cell& cell = cells_[static_cast<std::size_t>(j * nx_ + i)];
    double best = kMatchReach;
    const int nseg = static_cast<int>(f_.segments.size());
    for (int k : cell.segments) consider_segment(w, f_.segments[static_cast<std::size_t>(k)].a, f_.segments[static_cast<std::size_t>(k)].b, k, best, m);
    for (int k : cell.arcs) consider_arc(w, f_.arcs[static_cast<std::size_t>(k)], arc_ends_[static_cast<std::size_t>(k)], nseg + k, best, m);
    for (int k : cell.spots) consider_spot(w, f_.spots[static_cast<std::size_t>(k)], best, m);
    return m;
  }

 private:
  static constexpr double kCell = 0.5;
  // Distances computed two ways (distance_to_segment here, consider_segment per point) may differ in
  // their last bits: a marking is left out only when farther by more than this.
  static constexpr double kPruneMargin = 1e-6;
  struct Cell {
    std::vector<int> segments, arcs, spots;
  };
  const Field& f_;
  std::vector<ArcEnds> arc_ends_;  // one per arc: its cosines and sines, once
  double x0_ = 0, y0_ = 0;
  int nx_ = 0, ny_ = 0;
  std::vector<Cell> cells_;
};

}  // namespace

std::vector<MarkingMatch> match_markings(const Field& field, const std::vector<Eigen::Vector2d>& world) {
  const MarkingIndex index(field);
  std::vector<MarkingMatch> out;
  out.reserve(world.size());
  for (const auto& w : world) out.push_back(index.match(w));
  return out;
}

namespace {

// Pass 1: every point of every frame mapped to the world at the pose its image was exposed at and
// matched to its nearest marking; the residuals per noise class in `raw` for the gate.
std::vector<FrameWork> match_points(const std::vector<FrameRecord>& frames, const std::vector<Pose2>& poses, const Field& field, double h,
                                    std::array<std::vector<double>, kClasses>& raw) {
  std::vector<FrameWork> work(frames.size());
  const MarkingIndex index(field);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    FrameWork& fw = work[k];
    fw.pose = poses[k];
    fw.raw_points = frames[k].line_points.size();
    if (!frames[k].camera_ok) continue;
    fw.pts.reserve(fw.raw_points);
    const Eigen::Matrix2d rot = fw.pose.rotation();
    for (const auto& pf : frames[k].line_points) {
      const Eigen::Vector2d p(pf[0], pf[1]);
      const Eigen::Vector2d w = rot * p + fw.pose.translation();
      const MarkingMatch m = index.match(w);
      if (m.kind == 2) {
        ++fw.spot_points;
        continue;
      }
      if (m.kind == 0) {
        ++fw.far_points;
        continue;
      }
      PointRes q;
      const double r = p.norm();
      const bool grazing = r > 0 && std::fabs(m.normal.dot(rot * p) / r) < kGrazing;
      q.band = static_cast<std::uint8_t>(band_of(r) + (grazing ? static_cast<int>(kBands) : 0));
      q.residual = m.residual;
      const Eigen::Vector2d lever = w - fw.pose.translation();
      q.h = Eigen::Vector3d(m.normal.x(), m.normal.y(), lever.x() * m.normal.y() - lever.y() * m.normal.x());
      q.offset = static_cast<float>(m.normal.dot(w));
      q.marking = static_cast<std::int16_t>(m.marking);
      q.a = floor_tilt_jacobian(p, h).transpose() * (rot.transpose() * m.normal);
      raw[static_cast<std::size_t>(q.band)].push_back(q.residual);
      fw.pts.push_back(q);
    }
  }
  return work;
}

// What the run's own residuals say about its errors (the noise the bound uses).
struct NoiseModel {
  std::array<double, kClasses> total{}, centre{};  // each class's total spread and its centre (the first gate)
  std::array<std::size_t, kClasses> raw_count{};
  std::array<double, kClasses> sigma{};            // white noise per class, the tilt taken out
  std::array<std::size_t, kClasses> counts{};
  std::array<double, kClasses> medians{};
  std::size_t false_points = 0, spot_points = 0;
  double line_corr = 0.0;
  Eigen::Matrix2d tilt_cov = Eigen::Matrix2d::Zero();  // the vibration's covariance (roll, pitch)
  Eigen::Vector2d tilt_sigma = Eigen::Vector2d(std::nan(""), std::nan(""));
  std::vector<double> tx, ty;  // every fitted tilt: their median is a static tilt
};

// The first gate: kGateSigmas of each class's total spread (white and common together, as a false
// point is judged before any fit); a true point lies beyond it once in 16 000 for Gaussian errors.
void gate_points(std::vector<FrameWork>& work, std::array<std::vector<double>, kClasses>& raw, NoiseModel& nm) {
  for (std::size_t b = 0; b < kClasses; ++b) {
    nm.raw_count[b] = raw[b].size();
    nm.total[b] = std::max(kSigmaFloor, robust_sigma(std::move(raw[b]), &nm.centre[b]));
  }
  for (auto& fw : work) {
    nm.spot_points += fw.spot_points;
    nm.false_points += fw.far_points;
    for (auto& q : fw.pts) {
      const std::size_t b = static_cast<std::size_t>(q.band);
      q.near = std::isfinite(nm.total[b]) && std::fabs(q.residual - nm.centre[b]) <= kGateSigmas * nm.total[b];
      q.inlier = q.near;
    }
  }
}

// Pass 2: the per-frame tilt and the white noise, twice (weights from the total spread first,
// then from the white sigmas they gave). The second time, a point is first judged against its
// own frame's tilt: farther than kGateSigmas white sigmas from its marking once the frame's tilt
// is taken out, it is not that marking's (a far point can be 30 cm off through the tilt alone, so
// the first gate must be wide; this one is not).
void estimate_white_noise(std::vector<FrameWork>& work, double h, NoiseModel& nm) {
  nm.sigma = nm.total;
  for (int it = 0; it < 2; ++it) {
    if (it > 0)
      for (auto& fw : work)
        for (auto& q : fw.pts) {
          if (!q.near || !fw.tilt_fitted) continue;
          const double white = q.residual - tilt_row(q, fw.pose, h).dot(fw.tilt);
          q.inlier = std::fabs(white) <= kGateSigmas * nm.sigma[static_cast<std::size_t>(q.band)];
        }
    fit_tilts(work, nm.sigma, h);
    std::array<double, kClasses> white = white_sigmas(work, nm.sigma, h, &nm.counts, &nm.medians);
    for (std::size_t b = 0; b < kClasses; ++b) {
      // Too few points for a class of its own: the larger of its band's two (the conservative side
      // is the smaller information, a bound that cannot be beaten by a wrong noise figure).
      if (nm.counts[b] < kMinClassPoints) {
        const double other = white[(b + kBands) % kClasses];
        white[b] = nm.counts[(b + kBands) % kClasses] >= kMinClassPoints ? std::max(other, std::isfinite(white[b]) ? white[b] : other) : std::nan("");
      }
      nm.sigma[b] = std::isfinite(white[b]) ? std::max(kSigmaFloor, white[b]) : nm.total[b];
    }
  }
  for (const auto& fw : work)
    for (const auto& q : fw.pts) nm.false_points += !q.inlier;
  fit_tilts(work, nm.sigma, h);
  // Points on one marking in one frame share part of their error (the line's image as a whole: its
  // edges' blur and classification along its length), measured here and modelled as one offset per
  // marking and frame; ignoring it made the bound about a third too optimistic on the tracking path.
  nm.line_corr = line_correlation(work, nm.sigma, nm.medians, h);
}

// The tilt's spread over frames, less the fits' own noise: the vibration the frames carried. Its
// median is a static tilt (a mirror mounted askew): a bias, reported, not in the bound.
void estimate_tilt_spread(const std::vector<FrameWork>& work, NoiseModel& nm) {
  std::vector<double> vx, vy;
  for (const auto& fw : work)
    if (fw.tilt_fitted) {
      nm.tx.push_back(fw.tilt.x());
      nm.ty.push_back(fw.tilt.y());
      vx.push_back(fw.tilt_var(0, 0));
      vy.push_back(fw.tilt_var(1, 1));
    }
  if (nm.tx.size() >= 10) {
    const double sx = robust_sigma(nm.tx), sy = robust_sigma(nm.ty);
    nm.tilt_cov(0, 0) = std::max(0.0, sx * sx - median(vx));
    nm.tilt_cov(1, 1) = std::max(0.0, sy * sy - median(vy));
    nm.tilt_sigma = Eigen::Vector2d(std::sqrt(nm.tilt_cov(0, 0)), std::sqrt(nm.tilt_cov(1, 1)));
  }
}

// The compass readings against the truth: frame-to-frame differences (a slowly walking bias cancels
// in them) for its measured white noise, and the offsets for its median bias.
struct CompassReadings {
  std::vector<double> diffs, offsets;
};
CompassReadings compass_readings(const std::vector<FrameRecord>& frames) {
  CompassReadings c;
  std::optional<double> last;
  for (const auto& r : frames) {
    if (!r.heading) continue;
    const double e = angle_diff(*r.heading, r.truth.theta);
    c.offsets.push_back(e);
    if (last) c.diffs.push_back(angle_diff(e, *last) / std::sqrt(2.0));
    last = e;
  }
  return c;
}

// Pass 3's results: each frame's information, the single-frame bounds and the efficient
// estimator's error beside them (the bound's own check).
struct SingleFrame {
  std::vector<Eigen::Matrix3d> info;
  std::vector<Eigen::Vector3d> score;  // H^T R^-1 e at the truth, the compass's included
  std::map<std::string, std::size_t> why;  // frames without a finite bound, by reason
  Series series;
  std::size_t used_points = 0;
  double oracle_pos = 0, oracle_th = 0, oracle_bpos = 0, oracle_bth = 0;
};

// Pass 3: each frame's information and single-frame bound (into `out_frames`).
SingleFrame single_frame_bounds(const std::vector<FrameRecord>& frames, const std::vector<FrameWork>& work, const NoiseModel& nm,
                                bool compass, double compass_sigma, std::vector<FrameBound>& out_frames) {
  const std::size_t nf = frames.size();
  SingleFrame sf;
  sf.info.assign(nf, Eigen::Matrix3d::Zero());
  sf.score.assign(nf, Eigen::Vector3d::Zero());
  std::vector<BoundRow> rows;
  // Each marking's line number in the frame, in the order the frame's points first meet them (-1: not
  // met yet); `met` lists the markings to clear before the next frame.
  std::vector<int> line_of, met;
  for (std::size_t k = 0; k < nf; ++k) {
    const FrameWork& fw = work[k];
    rows.clear();
    for (int mk : met) line_of[static_cast<std::size_t>(mk)] = -1;
    met.clear();
    for (const auto& q : fw.pts) {
      if (!q.inlier) continue;
      const double s = nm.sigma[static_cast<std::size_t>(q.band)];
      BoundRow row;  // bound_row's, from what the match already computed
      row.h = q.h;
      row.var = (1.0 - nm.line_corr) * s * s;
      row.a = q.a;
      row.e = q.residual;
      const auto mk = static_cast<std::size_t>(q.marking);
      if (mk >= line_of.size()) line_of.resize(mk + 1, -1);
      if (line_of[mk] < 0) {
        line_of[mk] = static_cast<int>(met.size());
        met.push_back(q.marking);
      }
      row.line = line_of[mk];
      row.load = s;
      rows.push_back(row);
    }
    sf.used_points += rows.size();
    Eigen::Vector3d score = Eigen::Vector3d::Zero();
    if (frames[k].camera_ok) sf.info[k] = frame_information(rows, nm.tilt_cov, nm.line_corr, &score);
    const bool has_compass = compass && frames[k].heading.has_value();
    if (has_compass) {
      sf.info[k](2, 2) += 1.0 / (compass_sigma * compass_sigma);
      score(2) += angle_diff(*frames[k].heading, frames[k].truth.theta) / (compass_sigma * compass_sigma);
    }
    sf.score[k] = score;
    std::string reason;
    if (!frames[k].camera_ok) reason = "camera not ok";
    else if (fw.raw_points == 0) reason = "no points";
    else if (rows.empty()) reason = "no point near a marking";
    else if (rows.size() + (has_compass ? 1 : 0) < 3) reason = "fewer than 3 points";
    if (reason.empty()) {
      const CovarianceBound cb = invert_information(sf.info[k]);
      if (cb.finite) {
        out_frames[k].pos = std::sqrt(cb.cov(0, 0) + cb.cov(1, 1));
        out_frames[k].heading = std::sqrt(cb.cov(2, 2));
        sf.series.pos.push_back(*out_frames[k].pos);
        sf.series.heading.push_back(*out_frames[k].heading);
        // The efficient estimator's error on this frame: one generalized least-squares step from
        // the truth with the true association and the measured noise (its residual model is linear
        // there, so one step is its solution to first order). The residual's sign is that of
        // measured minus true, so the step is the estimate's error.
        const Eigen::Vector3d err = -cb.cov * score;
        sf.oracle_pos += err.head<2>().squaredNorm();
        sf.oracle_th += err(2) * err(2);
        sf.oracle_bpos += cb.cov(0, 0) + cb.cov(1, 1);
        sf.oracle_bth += cb.cov(2, 2);
        continue;
      }
      reason = singular_reason(fw);
    }
    ++sf.why[reason];
  }
  return sf;
}

// The posterior bound: pose and, with a wheel-scale error, the three scale factors (constant over
// the run, so their error is carried from frame to frame rather than drawn anew). Always six
// states: without a scale error their variance is 0 and they change nothing.
using M6 = Eigen::Matrix<double, 6, 6>;

// The motion model x_b = x_a (+) (s * u) at the true poses and the true increment u: its Jacobian
// F and the odometry's noise Q over the increment.
void motion_model(const Pose2& a, const Pose2& to, const BoundSetup& setup, M6& Fm, M6& Qm) {
  Fm.setIdentity();
  Qm.setZero();
  const Pose2 u = a.between(to);
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  Fm(0, 2) = -s * u.x - c * u.y;
  Fm(1, 2) = c * u.x - s * u.y;
  Fm(0, 3) = c * u.x;
  Fm(0, 4) = -s * u.y;
  Fm(1, 3) = s * u.x;
  Fm(1, 4) = c * u.y;
  Fm(2, 5) = u.theta;
  // sim/sensors.cpp: per step N(0, trans_sigma^2 d) on each axis (isotropic, so the same in the
  // world frame) and N(0, rot_sigma^2 |dtheta| + rot_per_trans^2 d) on the heading; summed over a
  // frame's steps, the variances add along the path.
  const double d = std::hypot(u.x, u.y), turn = std::fabs(u.theta);
  Qm(0, 0) = Qm(1, 1) = setup.trans_sigma * setup.trans_sigma * d;
  Qm(2, 2) = setup.rot_sigma * setup.rot_sigma * turn + setup.rot_per_trans * setup.rot_per_trans * d;
}

// Without the start pose, and after a kidnap, the localizer knows only that the robot is on the
// floor: a prior with the variance of a uniform position on it and a uniform heading. The posterior
// recursion and its check start from it and return to it alike.
Eigen::Vector3d floor_prior(const Field& field) {
  const double fx = 2.0 * field.half_floor_x(), fy = 2.0 * field.half_floor_y();
  return {fx * fx / 12.0, fy * fy / 12.0, kPi * kPi / 3.0};
}
M6 start_covariance(const BoundSetup& setup, const Eigen::Vector3d& uniform) {
  M6 P = M6::Zero();
  if (!setup.start_pose_given) P.topLeftCorner<3, 3>() = uniform.asDiagonal();
  P.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * setup.scale_sigma * setup.scale_sigma;
  return P;
}
// A kidnap: the pose's prior drawn anew, the scale's kept (it is the same wheels), and the carried
// image error with the temporal model (it is the same camera).
template <class M>
void reset_pose(M& P, const Eigen::Vector3d& uniform) {
  const Eigen::Index rest = P.rows() - 3;
  P.template topLeftCorner<3, 3>() = uniform.asDiagonal();
  P.topRightCorner(3, rest).setZero();
  P.bottomLeftCorner(rest, 3).setZero();
}

// With the temporal model: the six states and the carried error z (three) behind them.
using M9 = Eigen::Matrix<double, 9, 9>;
using V9 = Eigen::Matrix<double, 9, 1>;
M9 augmented(const M6& P6) {
  M9 P = M9::Zero();
  P.topLeftCorner<6, 6>() = P6;
  P.bottomRightCorner<3, 3>().setIdentity();
  return P;
}

// The posterior recursion over the frames: `white` takes the frames as independent; `carried` (when
// tc.rho > 0) adds the errors they carry over (TemporalCorrelation), and is the bound put in
// `out_frames` (else `white` is).
struct PosteriorSeries {
  Series white, carried;
};
PosteriorSeries posterior_bounds(const std::vector<FrameRecord>& frames, const std::vector<Pose2>& poses, const std::vector<Eigen::Matrix3d>& info,
                                 const std::vector<InfoRoots>& roots, const TemporalCorrelation& tc, const std::vector<bool>& reset_before,
                                 const BoundSetup& setup, const Field& field, std::vector<FrameBound>& out_frames) {
  const Eigen::Vector3d uniform = floor_prior(field);
  M6 P = start_covariance(setup, uniform);
  const bool temporal = tc.rho > 0;
  M9 P9 = augmented(P);
  PosteriorSeries out;
  M6 F = M6::Identity(), Q = M6::Zero(), Jz = M6::Zero();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    F.setIdentity();
    Q.setZero();
    if (reset_before[k]) {
      reset_pose(P, uniform);
      if (temporal) reset_pose(P9, uniform);
    } else if (k > 0) {
      motion_model(poses[k - 1], poses[k], setup, F, Q);
      if (temporal) predict_augmented(P9, F, Q, tc.a);
    }
    Jz.setZero();
    Jz.topLeftCorner<3, 3>() = info[k];
    P = posterior_step_impl<M6>(P, F, Q, Jz);
    if (temporal && roots[k].proj.any()) {
      // The check's filter's arithmetic on a state of zeros: the covariance is all the bound needs.
      V9 none = V9::Zero();
      correlated_update(P9, none, correlated_rows<9>(roots[k], tc.rho), tc.rho, Eigen::Vector3d::Zero());
    }
    // The recursion runs on the poses the images were exposed at; the pose scored is the frame's,
    // the latency later: carried forward through the odometry over it (its noise included). The
    // carried error z does not move the pose, so the pose and scale block is all that is carried.
    M6 Pf = P, Pf9 = P9.topLeftCorner<6, 6>();
    if (setup.latency_s > 0) {
      motion_model(poses[k], frames[k].truth, setup, F, Q);
      Pf = F * P * F.transpose() + Q;
      if (temporal) Pf9 = F * Pf9 * F.transpose() + Q;
    }
    const auto add = [](Series& sr, const M6& C) {
      sr.pos.push_back(std::sqrt(std::max(0.0, C(0, 0) + C(1, 1))));
      sr.heading.push_back(std::sqrt(std::max(0.0, C(2, 2))));
    };
    add(out.white, Pf);
    if (temporal) add(out.carried, Pf9);
    const Series& used = temporal ? out.carried : out.white;
    out_frames[k].ppos = used.pos.back();
    out_frames[k].pheading = used.heading.back();
  }
  if (!temporal) out.carried = out.white;
  return out;
}

// The posterior bound's own check on this run's data: the filter the bound describes (six states,
// the odometry's scale among them) run in error form with the true association, the measured noise
// and the recorded odometry. Its process error is the recorded odometry's slip: the increments
// less the scale fitted to them from the truth (least squares per axis over the run), whose own
// error is the scale states' starting error. Scored from the frames whose position variance is
// below (0.5 m)^2 (after a global start or a kidnap, once the filter has settled).
// `white` gets the filter that takes the frames as independent; `carried`, with tc.rho > 0, the
// temporal model's filter (the carried error z among its states: what the bound with carried
// errors describes) and the independent filter's errors against its covariance.
struct PosteriorCheck {
  Json white, carried;
};
PosteriorCheck posterior_check(const std::vector<FrameRecord>& frames, const std::vector<Pose2>& poses, const SingleFrame& sf,
                               const std::vector<InfoRoots>& roots, const std::vector<Eigen::Vector3d>& eta, const TemporalCorrelation& tc,
                               const std::vector<bool>& reset_before, const BoundSetup& setup, const Field& field) {
  const std::size_t nf = frames.size();
  Eigen::Vector3d num = Eigen::Vector3d::Zero(), den = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < nf; ++k) {
    if (reset_before[k]) continue;
    const Pose2 u = frames[k - 1].truth.between(frames[k].truth);
    const Pose2& o = frames[k].odometry;
    num += Eigen::Vector3d(o.x * u.x, o.y * u.y, o.theta * u.theta);
    den += Eigen::Vector3d(u.x * u.x, u.y * u.y, u.theta * u.theta);
  }
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  for (int i = 0; i < 3; ++i)
    if (den(i) > 1e-9) scale(i) = num(i) / den(i);
  const Eigen::Vector3d uniform = floor_prior(field);
  using V6 = Eigen::Matrix<double, 6, 1>;
  M6 P = start_covariance(setup, uniform);
  V6 e = V6::Zero();
  if (setup.scale_sigma > 0) e.tail<3>() = scale - Eigen::Vector3d::Ones();
  const bool temporal = tc.rho > 0;
  M9 P9 = augmented(P);
  V9 x9 = V9::Zero();
  x9.head<6>() = e;
  M6 F, Q, J = M6::Zero();
  V6 score = V6::Zero();
  // r: at the exposure pose; scored: at the frame's pose (the latency later); c: the temporal
  // model's filter; wc: the independent filter's errors against the temporal model's covariance.
  OracleResult r, scored, rc, scored_c, rwc, scored_wc;
  // At the pose scored, as the posterior bound: carried over the latency by the odometry, whose
  // noise there (not recorded: the odometry is per frame) enters both sides as the model's variance.
  // Fl, Ql: the motion over the latency, once per frame for the three filters.
  M6 Fl, Ql;
  const auto tally_scored = [&](const V6& err, const M6& Pk, OracleResult& out) {
    const V6 ef = Fl * err;
    const M6 Pf = Fl * Pk * Fl.transpose() + Ql;
    if (Pf(0, 0) + Pf(1, 1) > 0.25) return;
    out.pos_sq += ef.head<2>().squaredNorm() + Ql(0, 0) + Ql(1, 1);
    out.heading_sq += ef(2) * ef(2) + Ql(2, 2);
    out.pos_var += Pf(0, 0) + Pf(1, 1);
    out.heading_var += Pf(2, 2);
    ++out.frames;
  };
  for (std::size_t k = 0; k < nf; ++k) {
    if (reset_before[k]) {
      reset_pose(P, uniform);
      reset_pose(P9, uniform);
    } else if (k > 0) {
      motion_model(poses[k - 1], poses[k], setup, F, Q);
      const Pose2 u = frames[k - 1].truth.between(frames[k].truth);
      const Pose2& o = frames[k].odometry;
      const double sx = o.x - scale(0) * u.x, sy = o.y - scale(1) * u.y;
      const double c = std::cos(frames[k - 1].truth.theta), sn = std::sin(frames[k - 1].truth.theta);
      V6 nu = V6::Zero();
      nu << c * sx - sn * sy, sn * sx + c * sy, angle_diff(o.theta, scale(2) * u.theta), 0, 0, 0;
      if (setup.scale_sigma <= 0) nu.head<2>() += Eigen::Vector2d(c * (scale(0) - 1) * u.x - sn * (scale(1) - 1) * u.y, sn * (scale(0) - 1) * u.x + c * (scale(1) - 1) * u.y);
      e = F * e + nu;
      P = F * P * F.transpose() + Q;
      if (temporal) {
        x9.head<6>() = F * x9.head<6>() + nu;
        x9.tail<3>() *= tc.a;
        predict_augmented(P9, F, Q, tc.a);
      }
    }
    J.topLeftCorner<3, 3>() = sf.info[k];
    score.head<3>() = sf.score[k];
    oracle_update(e, P, J, score);
    oracle_tally(e, P, 0.25, r);
    if (setup.latency_s > 0) motion_model(poses[k], frames[k].truth, setup, Fl, Ql);
    if (temporal) {
      if (roots[k].proj.any()) correlated_update(P9, x9, correlated_rows<9>(roots[k], tc.rho), tc.rho, eta[k]);
      const M6 Pc = P9.topLeftCorner<6, 6>();
      oracle_tally(V6(x9.head<6>()), Pc, 0.25, rc);
      oracle_tally(e, Pc, 0.25, rwc);
      if (setup.latency_s > 0) {
        tally_scored(x9.head<6>(), Pc, scored_c);
        tally_scored(e, Pc, scored_wc);
      }
    }
    if (setup.latency_s > 0) tally_scored(e, P, scored);
  }
  if (setup.latency_s <= 0) {
    scored = r;
    scored_c = rc;
    scored_wc = rwc;
  }
  const auto ratio = [](double sq, double var) { return var > 0 ? Json(std::sqrt(sq / var)) : Json(nullptr); };
  const auto check = [&](const char* estimator, const OracleResult& at_frame, const OracleResult& at_exposure) {
    Json c{{"estimator", estimator}, {"frames", at_frame.frames}};
    const double n = static_cast<double>(at_frame.frames);
    c["position_rms_m"] = at_frame.frames ? Json(std::sqrt(at_frame.pos_sq / n)) : Json(nullptr);
    c["heading_rms_rad"] = at_frame.frames ? Json(std::sqrt(at_frame.heading_sq / n)) : Json(nullptr);
    c["position_ratio"] = ratio(at_frame.pos_sq, at_frame.pos_var);
    c["heading_ratio"] = ratio(at_frame.heading_sq, at_frame.heading_var);
    c["position_ratio_at_exposure"] = ratio(at_exposure.pos_sq, at_exposure.pos_var);
    c["heading_ratio_at_exposure"] = ratio(at_exposure.heading_sq, at_exposure.heading_var);
    return c;
  };
  PosteriorCheck out;
  out.white = check("the posterior bound's filter on this run: true association, the measured noise, the recorded odometry (its scale fitted from the truth)",
                    scored, r);
  if (temporal) {
    out.carried = check("the filter of the bound with carried errors on this run: the same, with the carried image error among its states", scored_c, rc);
    Json w = check("the filter that takes the frames as independent, its errors against the covariance of the bound with carried errors "
                   "(below 1 beyond sampling error would be a filter beating that bound)",
                   scored_wc, rwc);
    out.carried["independent_filter"] = w;
  } else {
    out.carried = out.white;
  }
  return out;
}

// The odometry's error per frame against the truth's increments, beside the model's prediction
// (the physics' wheel slip is not in the declared model and shows here).
struct OdometryError {
  std::vector<double> ox, oy, ot;
  double px = 0, pt = 0;  // the declared model's variance, summed over the frames
};
OdometryError odometry_error(const std::vector<FrameRecord>& frames, const std::vector<bool>& reset_before, const BoundSetup& setup) {
  OdometryError o;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    const FrameRecord& r = frames[k];
    if (reset_before[k]) continue;
    const Pose2 u = frames[k - 1].truth.between(r.truth);
    o.ox.push_back(r.odometry.x - u.x);
    o.oy.push_back(r.odometry.y - u.y);
    o.ot.push_back(angle_diff(r.odometry.theta, u.theta));
    const double d = std::hypot(u.x, u.y);
    o.px += setup.trans_sigma * setup.trans_sigma * d + std::pow(setup.scale_sigma * std::max(std::fabs(u.x), std::fabs(u.y)), 2);
    o.pt += setup.rot_sigma * setup.rot_sigma * std::fabs(u.theta) + setup.rot_per_trans * setup.rot_per_trans * d +
            std::pow(setup.scale_sigma * u.theta, 2);
  }
  return o;
}

// The bound's own check on this run's data: the efficient estimator reaches the bound only if the
// noise model is right (ratio 1); a ratio above 1 is error the model does not have (correlation
// between points it takes as independent, a bias), and the bound is then optimistic by about it.
Json check_json(const SingleFrame& sf) {
  const double nn = static_cast<double>(sf.series.pos.size());
  Json c{{"estimator", "generalized least squares from the true pose, true association, the measured noise"}, {"frames", sf.series.pos.size()}};
  c["position_rms_m"] = nn > 0 ? Json(std::sqrt(sf.oracle_pos / nn)) : Json(nullptr);
  c["heading_rms_rad"] = nn > 0 ? Json(std::sqrt(sf.oracle_th / nn)) : Json(nullptr);
  c["position_ratio"] = sf.oracle_bpos > 0 ? Json(std::sqrt(sf.oracle_pos / sf.oracle_bpos)) : Json(nullptr);
  c["heading_ratio"] = sf.oracle_bth > 0 ? Json(std::sqrt(sf.oracle_th / sf.oracle_bth)) : Json(nullptr);
  return c;
}

// summary.json's bound.noise: the measured noise per class, the declared beside it.
Json noise_json(const NoiseModel& nm, std::size_t used_points, double h, const BoundSetup& setup) {
  Json bands = Json::array(), measured = Json::array(), grazing = Json::array(), declared = Json::array(), band_pts = Json::array(),
       grazing_pts = Json::array(), band_med = Json::array(), band_total = Json::array();
  for (std::size_t i = 0; i < kBands; ++i) {
    const std::size_t g = i + kBands;
    bands.push_back(kBoundBands[i]);
    measured.push_back(nm.counts[i] ? num_or_null(nm.sigma[i]) : Json(nullptr));
    grazing.push_back(nm.counts[g] ? num_or_null(nm.sigma[g]) : Json(nullptr));
    declared.push_back(nullptr);
    band_pts.push_back(nm.counts[i]);
    grazing_pts.push_back(nm.counts[g]);
    band_med.push_back(nm.counts[i] ? num_or_null(nm.medians[i]) : Json(nullptr));
    band_total.push_back(nm.raw_count[i] ? num_or_null(nm.total[i]) : Json(nullptr));
  }
  Json n = {{"bands_m", bands},
            {"measured_sigma_m", measured},
            {"declared_sigma_m", declared},
            {"declared_why", "the profile declares pixel noise, not a line point's position noise (that comes from the image's sampling and edge "
                             "finding at each range): nothing to derive it from"},
            {"band_points", band_pts},
            {"grazing_sigma_m", grazing},
            {"grazing_points", grazing_pts},
            {"grazing_below", kGrazing},
            {"band_median_m", band_med},
            {"total_sigma_m", band_total},
            {"points", used_points},
            {"false_points", nm.false_points},
            {"spot_points", nm.spot_points},
            {"gate_sigmas", kGateSigmas},
            {"line_correlation", nm.line_corr},
            {"estimator", "1.4826 x MAD of the residuals at the true exposure pose, less each frame's fitted tilt"}};
  n["common_mode"] = {{"model", "a per-frame tilt of the mirror (roll, pitch) shifts each point by about (r^2 + h^2) / h per radian along its range"},
                      {"mount_height_m", h},
                      {"measured_sigma_rad", nm.tilt_sigma.allFinite() ? Json::array({nm.tilt_sigma.x(), nm.tilt_sigma.y()}) : Json(nullptr)},
                      {"declared_sigma_rad", setup.vibration_std},
                      {"declared_tilt_per_accel_rad_per_mps2", setup.tilt_per_accel},
                      {"static_rad", nm.tx.empty() ? Json(nullptr) : Json::array({median(nm.tx), median(nm.ty)})},
                      {"frames", nm.tx.size()}};
  return n;
}

}  // namespace

BoundPart bound_part(const RobotRecord& robot, const BoundSetup& setup) {
  BoundPart out;
  const auto& frames = robot.frames;
  const std::size_t nf = frames.size();
  out.frames.resize(nf);
  const double h = setup.mount_height;
  const Field& field = *setup.field;

  const std::vector<Pose2> poses = exposure_poses(robot, setup);
  std::array<std::vector<double>, kClasses> raw;
  std::vector<FrameWork> work = match_points(frames, poses, field, h, raw);
  NoiseModel nm;
  gate_points(work, raw, nm);
  estimate_white_noise(work, h, nm);
  estimate_tilt_spread(work, nm);
  // The compass: its declared white noise in the bound; measured beside it.
  const CompassReadings cr = compass_readings(frames);
  const bool compass = setup.has_heading_sensor && !cr.offsets.empty();
  const double compass_sigma = std::max(kCompassFloor, setup.heading_sigma);
  const SingleFrame sf = single_frame_bounds(frames, work, nm, compass, compass_sigma, out.frames);
  const std::vector<bool> reset_before = resets_before(frames, setup.resets);
  // The errors frames carry over to the next ones, measured from their whitened errors at the truth
  // over lags up to one second (a recursion's memory is shorter: a few frames to a second).
  std::vector<InfoRoots> roots(nf);
  std::vector<Eigen::Vector3d> eta(nf, Eigen::Vector3d::Zero());
  std::vector<bool> has_eta(nf, false);
  std::vector<int> segment(nf, 0);
  for (std::size_t k = 0; k < nf; ++k) {
    roots[k] = info_roots(sf.info[k]);
    eta[k] = whitened(roots[k], sf.score[k]);
    has_eta[k] = out.frames[k].pos.has_value();
    segment[k] = k == 0 ? 0 : segment[k - 1] + (reset_before[k] ? 1 : 0);
  }
  const int max_lag = static_cast<int>(std::clamp(std::lround(setup.camera_rate), 2L, 60L));
  const TemporalCorrelation tc = fit_temporal_correlation(eta, has_eta, segment, max_lag);
  const PosteriorSeries post = posterior_bounds(frames, poses, sf.info, roots, tc, reset_before, setup, field, out.frames);
  const OdometryError oe = odometry_error(frames, reset_before, setup);

  // Latency: the shift between the pose the image shows and the pose scored, a bias of any
  // localizer that does not carry its estimate forward by the odometry over the latency.
  double lat_pos = 0, lat_th = 0;
  for (std::size_t k = 0; k < nf; ++k) {
    lat_pos += std::pow(frames[k].truth.x - poses[k].x, 2) + std::pow(frames[k].truth.y - poses[k].y, 2);
    lat_th += std::pow(angle_diff(frames[k].truth.theta, poses[k].theta), 2);
  }

  const std::size_t scored = nf;
  Json& b = out.bound;
  b["single_frame"] = series_json(sf.series, scored);
  b["single_frame"]["check"] = check_json(sf);
  const PosteriorCheck pc = posterior_check(frames, poses, sf, roots, eta, tc, reset_before, setup, field);
  const char* prior = setup.start_pose_given ? "the true start pose (the localizer was given it)"
                                             : "uniform over the floor and heading (the localizer was not given its start)";
  b["posterior"] = series_json(post.carried, scored);
  b["posterior"]["prior"] = prior;
  if (!setup.resets.empty()) b["posterior"]["restarts_at_s"] = setup.resets;
  b["posterior"]["check"] = pc.carried;
  Json carried{{"share", tc.rho},
               {"per_frame", tc.a},
               {"memory_frames", tc.rho > 0 && tc.a > 0 && tc.a < 1 ? Json(-1.0 / std::log(tc.a)) : Json(nullptr)},
               {"lags", tc.lags},
               {"pairs", tc.pairs},
               {"model", "a share of each frame's whitened error carried to the next frames with a per-frame coefficient, fitted to "
                         "the autocorrelation of the frames' errors at the truth over lags 1..lags"}};
  Json acf = Json::array();
  for (double v : tc.autocorrelation) acf.push_back(num_or_null(v));
  carried["autocorrelation"] = acf;
  if (!tc.why.empty()) carried["why_independent"] = tc.why;
  b["posterior"]["carried_errors"] = carried;
  b["posterior_white"] = series_json(post.white, scored);
  b["posterior_white"]["prior"] = prior;
  b["posterior_white"]["check"] = pc.white;
  b["posterior_white"]["model"] = "each frame's errors independent of the other frames' (beside, for comparison)";
  std::size_t no_bound = 0;
  Json why_j = Json::object();
  for (const auto& [k, v] : sf.why) {
    why_j[k] = v;
    no_bound += v;
  }
  b["no_bound"] = {{"frames", no_bound}, {"why", why_j}};
  b["noise"] = noise_json(nm, sf.used_points, h, setup);
  if (setup.has_heading_sensor) {
    b["compass"] = {{"declared_sigma_rad", setup.heading_sigma},
                    {"used_sigma_rad", compass_sigma},
                    {"measured_sigma_rad", cr.diffs.size() >= 2 ? num_or_null(robust_sigma(cr.diffs)) : Json(nullptr)},
                    {"measured_bias_rad", cr.offsets.empty() ? Json(nullptr) : num_or_null(median(cr.offsets))},
                    {"readings", cr.offsets.size()}};
  }
  const double no = static_cast<double>(oe.ox.size());
  b["odometry"] = {{"declared_sigma", oe.ox.empty() ? Json(nullptr) : Json::array({std::sqrt(oe.px / no), std::sqrt(oe.px / no), std::sqrt(oe.pt / no)})},
                   {"measured_sigma", oe.ox.size() >= 2 ? Json::array({robust_sigma(oe.ox), robust_sigma(oe.oy), robust_sigma(oe.ot)}) : Json(nullptr)},
                   {"units", "per frame: x, y (m, robot frame), theta (rad)"},
                   {"frames", oe.ox.size()}};
  b["latency"] = {{"latency_s", setup.latency_s},
                  {"position_shift_rms_m", nf ? Json(std::sqrt(lat_pos / static_cast<double>(nf))) : Json(nullptr)},
                  {"heading_shift_rms_rad", nf ? Json(std::sqrt(lat_th / static_cast<double>(nf))) : Json(nullptr)},
                  {"treatment", "a bias, not noise: the bound is on the pose the image was exposed at; the shift to the frame's pose is "
                                "what a localizer that does not carry its estimate forward adds"}};
  b["assumptions"] = "known association, measured Gaussian noise, unbiased estimator";
  return out;
}

RobotBound bound_from_part(const RobotRecord& robot, const BoundSetup& setup, BoundPart part) {
  RobotBound out;
  out.frames = std::move(part.frames);
  out.bound = std::move(part.bound);
  const std::size_t nf = robot.frames.size();
  // A robot standing still has odometry too (increments of zero tell it so): what decides is whether
  // the frames carry odometry at all, which the setup says.
  const bool odometry = setup.has_odometry;
  // Recomputed rather than kept: a pass over the frames, and what a cached part would otherwise carry.
  const std::vector<Pose2> poses = setup.latency_s > 0 ? exposure_poses(robot, setup) : std::vector<Pose2>();
  std::vector<std::optional<double>> sp(nf), sh(nf), pp(nf), ph(nf);
  for (std::size_t k = 0; k < nf; ++k) {
    sp[k] = out.frames[k].pos;
    sh[k] = out.frames[k].heading;
    pp[k] = out.frames[k].ppos;
    ph[k] = out.frames[k].pheading;
  }
  const std::vector<Pose2>* exp = setup.latency_s > 0 ? &poses : nullptr;
  out.efficiency_single = efficiency_json(robot, sp, sh, "single_frame", exp);
  out.efficiency = odometry ? efficiency_json(robot, pp, ph, "posterior", exp) : out.efficiency_single;
  if (!setup.excluded.empty()) {
    // After a kidnap the posterior bound starts from a prior as wide as the floor: a bound on the
    // average over where the robot may be put, which one run's error (the distance it was carried)
    // can lie below while the robot is blind. Tracking is judged without those intervals.
    out.efficiency_single["tracking_phase"] = efficiency_json(robot, sp, sh, "single_frame", exp, &setup.excluded);
    out.efficiency["tracking_phase"] = efficiency_json(robot, odometry ? pp : sp, odometry ? ph : sh, odometry ? "posterior" : "single_frame", exp, &setup.excluded);
  }
  if (odometry && !setup.resets.empty()) {
    // Said where the number is, not only in the docs: a reader of summary.json alone would otherwise
    // take an efficiency below 1 over all frames for a localizer beating the bound.
    out.efficiency["all_frames_note"] =
        "over all frames, the blind ones after each kidnap included: their posterior bound starts from a prior as wide as the floor, an "
        "average over where the robot may be put, which one run's error (how far it was carried) can lie below; the tracking phase's "
        "figure is the one to read";
  }
  return out;
}

RobotBound bound_robot(const RobotRecord& robot, const BoundSetup& setup) { return bound_from_part(robot, setup, bound_part(robot, setup)); }

}  // namespace omniloc::harness
