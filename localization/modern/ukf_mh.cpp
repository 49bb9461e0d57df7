#include "localization/modern/ukf_mh.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "localization/matching.hpp"
#include "localization/vision/colour_table.hpp"

namespace omniloc::modern {

namespace {

const ParamList<MotionNoise>& motion_params() {
  using P = MotionNoise;
  static const ParamList<P> list = {
      number_param("odo_trans", &P::trans_per_sqrt_m, 0.0, 1.0, "m/sqrt(m)", "odometry noise: random walk of x and y per square root of the distance travelled"),
      number_param("odo_scale", &P::scale, 0.0, 0.5, "", "odometry noise: wheel-scale error, a fraction of the distance"),
      number_param("odo_rot", &P::rot_per_sqrt_rad, 0.0, 1.0, "rad/sqrt(rad)", "odometry noise: random walk of theta per square root of the angle turned"),
      number_param("odo_rot_per_m", &P::rot_per_sqrt_m, 0.0, 1.0, "rad/sqrt(m)", "odometry noise: random walk of theta per square root of the distance travelled"),
      number_param("odo_floor_xy", &P::floor_xy, 0.0, 1.0, "m", "odometry noise floor per frame in x and y"),
      number_param("odo_floor_theta", &P::floor_theta, 0.0, 1.0, "rad", "odometry noise floor per frame in theta"),
  };
  return list;
}

const ParamList<HypothesisSetParams>& set_params() {
  using P = HypothesisSetParams;
  static const ParamList<P> list = {
      integer_param("max_hypotheses", &P::max_hypotheses, 1, 100, "hypotheses kept at most (B-Human's SelfLocator: a handful)"),
      positive_param("merge_xy", &P::merge_xy, 10.0, "m", "hypotheses closer than this (and merge_theta) are merged"),
      positive_param("merge_theta", &P::merge_theta, 3.2, "rad", "hypotheses closer than this in heading (and merge_xy) are merged"),
      number_param("prune_validity", &P::prune_validity, 0.0, 1.0, "", "hypotheses below this validity are pruned"),
      number_param("prune_gap", &P::prune_gap, 0.0, 1.0, "", "hypotheses this much less valid than the most valid one are pruned"),
      number_param("prune_age", &P::prune_age, 0.0, 100.0, "s", "younger hypotheses are not pruned"),
  };
  return list;
}

const ParamList<AlternativePoseParams>& alt_params() {
  using P = AlternativePoseParams;
  static const ParamList<P> list = {
      integer_param("alt_pool", &P::pool, 1, 100, "alternative poses: candidates kept from frame to frame (Falcons)"),
      integer_param("alt_screened", &P::screened, 0, 100000, "alternative poses: fresh restarts screened per round while no hypothesis is valid"),
      integer_param("alt_refined", &P::refined, 0, 100, "alternative poses: best screened restarts refined by the simplex"),
      positive_param("alt_c_wide", &P::c_wide, 20.0, "m", "alternative poses: error scale of screening and the first simplex stage"),
      positive_param("alt_c", &P::c, 5.0, "m", "alternative poses: error scale of the final stage and of the comparison (Tribots: 250 mm)"),
      integer_param("alt_evaluations", &P::max_evaluations, 4, 100000, "alternative poses: simplex evaluations per stage at most"),
      positive_param("alt_step_xy", &P::step_xy, 5.0, "m", "alternative poses: initial simplex size in x and y"),
      positive_param("alt_step_theta", &P::step_theta, 3.2, "rad", "alternative poses: initial simplex size in theta"),
      positive_param("alt_tolerance", &P::tolerance, 1.0, "m, rad", "alternative poses: the simplex stops when smaller than this"),
  };
  return list;
}

}  // namespace

const ParamList<UkfMhParams>& UkfMhParams::params() {
  using P = UkfMhParams;
  static const ParamList<P> list = {
      integer_param("max_points", &P::max_points, 3, 100000, "line points evenly subsampled beyond this"),
      integer_param("min_points", &P::min_points, 1, 10000, "fewer line points: no sensor update, odometry only (matching's default)"),
      positive_param("point_sigma", &P::point_sigma, 2.0, "m", "a line point's own noise at range weight_ref"),
      positive_param("weight_d", &P::weight_d, 100.0, "m", "point noise grows as (weight_d^2 + r^2) with the range r (NuBot's range weights: 2.5 m)"),
      positive_param("weight_ref", &P::weight_ref, 100.0, "m", "the range whose points have noise point_sigma (NuBot: 1.5 m)"),
      number_param("grazing_below", &P::grazing_below, 0.0, 1.0, "",
                   "a point whose scan ray meets its marking at a cosine (the marking's normal . the ray, in absolute value) below this is a grazing point: its white run is not a whole crossing of the line (the scan lines accept up to 3 line widths and 2 px); used where grazing_spread > 0"),
      number_param("grazing_spread", &P::grazing_spread, 0.0, 10.0, "line widths",
                   "a grazing point's added standard deviation across its marking, in the field's line widths (its run is a piece of the line, anywhere across its width: 1 / sqrt(12)); 0: no grazing class"),
      number_param("marking_sd", &P::marking_sd, 0.0, 1.0, "m",
                   "standard deviation of an offset shared by a frame's points on one marking (the line's image as a whole), marginalised per frame; 0: points independent (the accuracy bound's line correlation times its white point noise, measured on recordings outside the evaluation sets: 0.32 x 1.3 cm = 0.4 cm; 0.5 cm on the images before a4652a0)"),
      number_param("tilt_sd", &P::tilt_sd, 0.0, 0.2, "rad",
                   "the frame's camera tilt (roll and pitch, each), a nuisance marginalised per frame with each point's geometry; 0: not modelled (JSON default: the camera's declared vibration, the robot profile's 0.3 deg)"),
      number_param("mount_height", &P::mount_height, 0.0, 5.0, "m",
                   "the mirror viewpoint's height of the tilt's geometry; 0: unknown, tilt not modelled (JSON default: the camera's declared mount height)"),
      number_param("common_sd_xy", &P::common_sd_xy, 0.0, 2.0, "m", "where the tilt is not modelled (tilt_sd or mount_height 0): a frame-common error of the points' pose, which no number of points averages out"),
      number_param("common_sd_theta", &P::common_sd_theta, 0.0, 1.0, "rad", "where the tilt is not modelled: a frame-common heading error of the points"),
      positive_param("corridor", &P::corridor, 10.0, "m", "points farther than this from their nearest marking are not associated"),
      positive_param("gate_sigmas", &P::gate_sigmas, 100.0, "", "innovation gate of a point in standard deviations"),
      number_param("white_gate_sigmas", &P::white_gate_sigmas, 0.0, 100.0, "",
                   "a second gate where the tilt is modelled: a point whose residual, once the frame's tilt fitted to its points is taken out, exceeds this many of its white spread (white_sigma, its marking's offset, the pose's spread) is not that marking's; 0: none"),
      positive_param("white_sigma", &P::white_sigma, 1.0, "m", "a line point's own spread once the frame's tilt is taken out (the second gate's unit)"),
      positive_param("inlier_sigmas", &P::inlier_sigmas, 100.0, "", "a point fits (validity) when within this many standard deviations of its marking"),
      integer_param("iterations", &P::iterations, 1, 20, "iterated update: association and linearisation again at the new mean"),
      number_param("latency", &P::latency, 0.0, 1.0, "s", "the image is this much older than the odometry; 0: moved to no time (JSON default: the camera's declared latency, the robot profile's 0.033)"),
      positive_param("validity_time", &P::validity_time, 100.0, "s", "time constant of each hypothesis's validity filter"),
      number_param("valid_min", &P::valid_min, 0.0, 1.0, "", "validity from which the best hypothesis is reported valid"),
      number_param("hysteresis", &P::hysteresis, 0.0, 1.0, "", "another hypothesis must be this much more valid to take the lead"),
      integer_param("trust_frames", &P::trust_frames, 1, 1000, "a hypothesis whose last trust_frames updates fit trust_share of the points on average is valid at once"),
      number_param("trust_share", &P::trust_share, 0.0, 1.1, "", "mean share of fitting points over trust_frames updates that makes a hypothesis valid at once (above 1: never)"),
      positive_param("compass_gate", &P::compass_gate, 3.2, "rad", "a hypothesis this far from the compass heading fits nothing that frame"),
      number_param("compass_sigma", &P::compass_sigma, 0.0, 1.0, "rad",
                   "the compass's white noise: each reading is fused as theta + bias + this noise; 0: the compass only gates (compass_gate)"),
      number_param("compass_bias_walk", &P::compass_bias_walk, 0.0, 1.0, "rad/sqrt(s)", "random walk of the compass's bias, estimated beside each hypothesis's pose"),
      positive_param("compass_bias_sd", &P::compass_bias_sd, 3.2, "rad", "a new hypothesis's prior standard deviation of the compass bias"),
      positive_param("new_sd_xy", &P::new_sd_xy, 10.0, "m", "a proposed pose's initial standard deviation in x and y"),
      positive_param("new_sd_theta", &P::new_sd_theta, 3.2, "rad", "a proposed pose's initial standard deviation in theta"),
      integer_param("alt_points", &P::alt_points, 3, 100000, "alternative poses: line points of the fit"),
      number_param("alt_period", &P::alt_period, 0.0, 1000.0, "s", "alternative poses: while tracking, one search round this often"),
      integer_param("alt_tracking_restarts", &P::alt_tracking_restarts, 0, 100000, "alternative poses: fresh restarts per round while tracking"),
      number_param("alt_margin", &P::alt_margin, 0.0, 1.0, "", "a proposal enters when its score beats the best hypothesis's by this (mean e(d) at alt_c)"),
      number_param("cell", &P::cell, 0.005, 0.5, "m", "distance-map cell of the fit (Tribots: 50 mm)"),
  };
  return list;
}

Json UkfMhParams::schema() {
  const UkfMhParams d;
  Json s = params_schema(params(), d);
  s.update(params_schema(motion_params(), d.motion));
  s.update(params_schema(set_params(), d.set));
  s.update(params_schema(alt_params(), d.alt));
  return s;
}

UkfMhParams UkfMhParams::from_json(JsonReader& r, const DeclaredCamera& camera) {
  UkfMhParams p;
  // A team measures its camera's latency once and configures its localizer with it (B-Human
  // timestamps each image and predicts the pose to the image's time): the declared value is the
  // default, a number given here overrides it. The same for the mirror's height (a calibration
  // fact) and the camera's vibration (measured once on the robot).
  p.latency = camera.latency;
  p.tilt_sd = camera.vibration;
  p.mount_height = camera.mount_height;
  read_params(r, p, params());
  read_params(r, p.motion, motion_params());
  read_params(r, p.set, set_params());
  read_params(r, p.alt, alt_params());
  p.alt.distinct_xy = p.set.merge_xy;
  p.alt.distinct_theta = p.set.merge_theta;
  return p;
}

UkfMhLocalizer::UkfMhLocalizer(const Field& field, const UkfMhParams& p, std::uint64_t seed, const std::string& cache_dir)
    : p_(p),
      field_(field),
      map_(field, p.cell, cache_dir),
      assoc_(field),
      alt_(p.alt, field.half_floor_x(), field.half_floor_y(), seed),
      grazing_var_(std::pow(p.grazing_spread * field.line_width, 2)) {}

namespace {
// One point of a frame placed at a linearisation pose: its marking's local model there and what the
// update and the second gate read of it.
struct PointAt {
  LocalMarking m;
  Eigen::Vector2d w{0.0, 0.0}, a{0.0, 0.0};  ///< world position (m); d(distance)/d(tilt) (m/rad)
  double var = 0.0, tilt_var = 0.0;          ///< its noise variance, and the tilt's (m^2)
  double v = 0.0, white_var = 0.0;           ///< second gate: signed distance (m), white variance (m^2)
  bool ok = false, in_fit = false;           ///< associated within the corridor; in the tilt's fit
};
}  // namespace

double incidence_variance(double own_var, const Eigen::Vector2d& ray, const Eigen::Vector2d& normal, double grazing_below, double grazing_var) {
  return std::fabs(ray.dot(normal)) < grazing_below ? own_var + grazing_var : own_var;
}

void UkfMhLocalizer::reset(const std::optional<Pose2>& start) {
  set_.clear();
  alt_.clear();
  history_.clear();
  next_id_ = 0;
  best_id_ = -1;
  was_valid_ = false;
  last_t_.reset();
  last_search_t_ = -1e300;
  proposals_ = 0;
  if (start) {
    Hypothesis h;
    h.ukf.reset(*start, Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.02 * 0.02).asDiagonal());
    if (p_.compass_sigma > 0) h.ukf.start_bias(p_.compass_bias_sd * p_.compass_bias_sd);
    h.validity = 1.0;  // a given start is stood behind until the points say otherwise
    h.age = p_.set.prune_age;
    h.id = next_id_++;
    set_.push_back(h);
    best_id_ = h.id;
  }
}

Pose2 UkfMhLocalizer::exposure_to_now(double t) const {
  if (!(p_.latency > 0) || history_.empty()) return Pose2();
  // The motion from t - latency to t, composed oldest first from the frames' increments (the
  // oldest in part, in proportion of its interval: constant velocity within a frame).
  const double from = t - p_.latency;
  Pose2 m;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (it->t1 <= from) break;
    const double span = it->t1 - it->t0;
    const double f = span > 0 ? std::clamp((it->t1 - std::max(it->t0, from)) / span, 0.0, 1.0) : 1.0;
    const Pose2 part(f * it->delta.x, f * it->delta.y, f * it->delta.theta);
    m = part.compose(m);
  }
  return m;
}

void UkfMhLocalizer::prepare_points(const std::vector<Eigen::Vector2d>& image, double t) {
  const Pose2 back = exposure_to_now(t).inverse();
  frame_.clear();
  frame_.reserve(image.size());
  for (const auto& q : image) frame_.push_back(back.transform(q));
  const double c = std::cos(back.theta), s = std::sin(back.theta);
  Eigen::Matrix2d rot;
  rot << c, -s, s, c;
  ray_.clear();
  if (grazing_var_ > 0 && p_.grazing_below > 0) {
    // The scan ray ran from the robot as it was at the exposure: its direction is the image point's.
    ray_.reserve(image.size());
    for (const auto& q : image) {
      const double r = q.norm();
      ray_.push_back(r > 0 ? Eigen::Vector2d(rot * q / r) : Eigen::Vector2d(1.0, 0.0));
    }
  }
  tilt_.clear();
  if (!p_.tilt_modelled()) return;
  // The tilt turns the camera, whose axes are the robot's at the exposure: a point's move is
  // computed where the image saw it and turned into the robot frame of now.
  tilt_.reserve(image.size());
  for (const auto& q : image) tilt_.push_back(rot * floor_tilt_jacobian(q, p_.mount_height));
}

double UkfMhLocalizer::tilt_variance(std::size_t i, const Eigen::Vector2d& g, double c, double s, Eigen::Vector2d* a) const {
  if (tilt_.empty()) {
    if (a) a->setZero();
    return 0.0;
  }
  // The distance's change per radian of tilt: the point's move (robot frame) along the marking's
  // normal turned into the robot frame (c, s: the heading's cosine and sine).
  const Eigen::Vector2d n_robot(c * g.x() + s * g.y(), -s * g.x() + c * g.y());
  const Eigen::Vector2d row = tilt_[i].transpose() * n_robot;
  if (a) *a = row;
  return p_.tilt_sd * p_.tilt_sd * row.squaredNorm();
}

bool UkfMhLocalizer::contradicted(const Eigen::Vector3d& q, std::optional<double> heading, const Observations& obs) const {
  if (heading && std::fabs(angle_diff(q.z(), *heading)) > p_.compass_gate) return true;
  // Goal colours (the legacy field): a goal's colour seen more than 90 degrees from where the pose
  // puts that goal says the pose is the twin.
  for (const auto& b : obs.blobs) {
    if (b.kind != Blob::Kind::kRegion) continue;
    const Goal* match = nullptr;
    int n = 0;
    for (const auto& g : field_.goals)
      if (g.colour != "white" && landmark_colour_class(g.colour) == b.colour) match = &g, ++n;
    if (n != 1) continue;
    const double want = std::atan2(-q.y(), match->goal_line_x - q.x()) - q.z();
    if (std::fabs(angle_diff(want, b.bearing)) > 0.5 * kPi) return true;
  }
  return false;
}

double UkfMhLocalizer::point_variance(const Eigen::Vector2d& o) const {
  const double d2 = p_.weight_d * p_.weight_d;
  return p_.point_sigma * p_.point_sigma * (d2 + o.squaredNorm()) / (d2 + p_.weight_ref * p_.weight_ref);
}

double UkfMhLocalizer::noise_variance(std::size_t i, double own, const Eigen::Vector2d& g, double c, double s) const {
  if (i >= ray_.size()) return own;  // no grazing class
  // The marking's normal in the robot frame, against the ray there.
  return incidence_variance(own, ray_[i], Eigen::Vector2d(c * g.x() + s * g.y(), -s * g.x() + c * g.y()), p_.grazing_below, grazing_var_);
}

double UkfMhLocalizer::inlier_share(const Eigen::Vector3d& q) const {
  const std::vector<Eigen::Vector2d>& pts = frame_;
  if (pts.empty()) return 0.0;
  const double common_var = p_.common_xy_var();
  const double c = std::cos(q.z()), s = std::sin(q.z());
  int fit = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector2d& o = pts[i];
    const Eigen::Vector2d w(q.x() + c * o.x() - s * o.y(), q.y() + s * o.x() + c * o.y());
    const LocalMarking m = assoc_.associate(w);
    if (m.marking < 0) continue;
    const Eigen::Vector2d g = m.gradient(w);
    const double tilt_var = tilt_variance(i, g, c, s, nullptr);
    const double own = noise_variance(i, point_variance(o), g, c, s);
    if (m.distance * m.distance <= p_.inlier_sigmas * p_.inlier_sigmas * (own + common_var + tilt_var)) ++fit;
  }
  return static_cast<double>(fit) / static_cast<double>(pts.size());
}

void UkfMhLocalizer::sensor_update(Hypothesis& h, const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading, const Observations& obs,
                                   double dt) {
  // Per point: its noise variance (grows with range, NuBot's weights read as variances), and where
  // its scan ray grazes the marking it is associated with, the spread across the line's width.
  const double common_var = p_.common_xy_var();
  thread_local std::vector<double> own_var;
  own_var.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) own_var[i] = point_variance(pts[i]);
  // Points on one marking share an offset of standard deviation marking_sd (in metres, the same for
  // each of them, as the accuracy bound measures it); what is left of a point's variance is its own
  // (never below half of it: a shared part larger than the whole is a contradiction of parameters).
  const double shared_var = p_.marking_sd * p_.marking_sd;
  const bool white_gate = p_.white_gate_sigmas > 0 && !tilt_.empty();
  // Point i placed at the linearisation pose (heading cosine c, sine s) and associated; its model
  // there when within the corridor (q.ok).
  const auto place = [&](std::size_t i, const Eigen::Vector3d& at, double c, double s, PointAt& q) {
    const Eigen::Vector2d& o = pts[i];
    q.w = Eigen::Vector2d(at.x() + c * o.x() - s * o.y(), at.y() + s * o.x() + c * o.y());
    q.m = assoc_.associate(q.w);
    q.ok = q.m.marking >= 0 && q.m.distance <= p_.corridor;
    if (!q.ok) return;
    const Eigen::Vector2d g = q.m.gradient(q.w);
    q.tilt_var = tilt_variance(i, g, c, s, &q.a);
    q.var = noise_variance(i, own_var[i], g, c, s);
  };
  const auto linearise = [&](const Eigen::Vector3d& at, const SigmaPoints& sp, InformationSum& sum) {
    const double c = std::cos(at.z()), s = std::sin(at.z());
    // The frame's tilt fitted to its points at this pose (the first gate's survivors, weighted by
    // their noise, with the tilt's prior): what is left of a point's residual after it is that
    // point's own error, whose spread is small (the far points' large spread is the tilt's). Fitted
    // twice: the second time without the points the first fit leaves beyond the gate (a far
    // outlier's long lever on the tilt would otherwise hide part of its residual). The points'
    // placement is kept for the update below.
    Eigen::Vector2d tilt_hat = Eigen::Vector2d::Zero();
    thread_local std::vector<PointAt> placed;
    if (white_gate) {
      placed.resize(pts.size());
      for (std::size_t i = 0; i < pts.size(); ++i) {
        PointAt& q = placed[i];
        place(i, at, c, s, q);
        if (!q.ok) continue;
        q.v = q.m.value(q.w.x(), q.w.y());
        q.in_fit = q.v * q.v <= p_.gate_sigmas * p_.gate_sigmas * (q.var + q.tilt_var + common_var);
        q.white_var = p_.white_sigma * p_.white_sigma + (q.var - own_var[i]) + shared_var;
      }
      const Eigen::Matrix2d prior = Eigen::Matrix2d::Identity() / (p_.tilt_sd * p_.tilt_sd);
      for (int pass = 0; pass < 2; ++pass) {
        Eigen::Matrix2d ai = prior;
        Eigen::Vector2d ar = Eigen::Vector2d::Zero();
        for (const PointAt& q : placed) {
          if (!q.ok || !q.in_fit) continue;
          if (pass > 0) {
            const double white = q.v + q.a.dot(tilt_hat);
            if (white * white > p_.white_gate_sigmas * p_.white_gate_sigmas * q.white_var) continue;
          }
          ai.noalias() += q.a * q.a.transpose() / q.var;
          ar.noalias() -= q.a * (q.v / q.var);
        }
        tilt_hat = ai.ldlt().solve(ar);
      }
    }
    std::array<double, 6> cs{}, sn{};
    for (int k = 0; k < 6; ++k) cs[static_cast<std::size_t>(k)] = std::cos(sp[k].z()), sn[static_cast<std::size_t>(k)] = std::sin(sp[k].z());
    PointAt here;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector2d& o = pts[i];
      if (!white_gate) place(i, at, c, s, here);
      const PointAt& q = white_gate ? placed[i] : here;
      if (!q.ok) continue;
      const LocalMarking& m = q.m;
      std::array<double, 6> hv{};
      for (int k = 0; k < 6; ++k) {
        const auto ku = static_cast<std::size_t>(k);
        hv[ku] = m.value(sp[k].x() + cs[ku] * o.x() - sn[ku] * o.y(), sp[k].y() + sn[ku] * o.x() + cs[ku] * o.y());
      }
      const SigmaPoints::Predicted pr = sp.predict(hv);
      // The gate: the innovation against its whole spread (pose, point, tilt, frame-common error).
      const double spread = pr.var + q.var + q.tilt_var + common_var;
      if (pr.mean * pr.mean > p_.gate_sigmas * p_.gate_sigmas * spread) continue;
      if (white_gate) {
        const double white = q.v + q.a.dot(tilt_hat);
        if (white * white > p_.white_gate_sigmas * p_.white_gate_sigmas * (q.white_var + pr.var)) continue;
      }
      if (shared_var > 0)
        sp.add(hv, pr, 0.0, std::max(q.var - shared_var, 0.5 * q.var), sum, tilt_.empty() ? nullptr : &q.a, m.marking, p_.marking_sd);
      else
        sp.add(hv, pr, 0.0, q.var, sum, tilt_.empty() ? nullptr : &q.a);
    }
  };
  Eigen::Matrix3d common = Eigen::Matrix3d::Zero();
  common(0, 0) = common(1, 1) = common_var;
  common(2, 2) = p_.tilt_modelled() ? 0.0 : p_.common_sd_theta * p_.common_sd_theta;
  const Eigen::Matrix2d tilt_cov = tilt_.empty() ? Eigen::Matrix2d::Zero() : Eigen::Matrix2d(p_.tilt_sd * p_.tilt_sd * Eigen::Matrix2d::Identity());
  h.ukf.update(linearise, p_.iterations, common, tilt_cov, shared_var > 0 ? 1.0 : 0.0);
  h.inliers = inlier_share(h.ukf.mean());
  const Eigen::Vector3d& q = h.ukf.mean();
  const double evidence = contradicted(q, heading, obs) ? 0.0 : h.inliers;
  const double alpha = 1.0 - std::exp(-std::max(dt, 0.0) / p_.validity_time);
  h.validity += alpha * (evidence - h.validity);
  // Consistent evidence: a pose that explained nearly every point in each of its last few updates
  // is right beyond reasonable doubt well before the low-pass filter says so. The best wrong poses
  // of the field explain at most about three quarters of a frame's points, so a mean of trust_share
  // over trust_frames frames is many standard deviations of that mean beyond them
  // (docs/modern_localizer.md); the frame a proposal was fitted to is not among them (the best of
  // many restarts on that frame's points flatters it).
  h.recent.push_back(evidence);
  if (static_cast<int>(h.recent.size()) > p_.trust_frames) h.recent.erase(h.recent.begin());
  if (static_cast<int>(h.recent.size()) == p_.trust_frames) {
    double sum = 0.0;
    for (const double e : h.recent) sum += e;
    if (sum >= p_.trust_share * p_.trust_frames) h.validity = std::max(h.validity, p_.valid_min);
  }
}

void UkfMhLocalizer::search(const std::vector<Eigen::Vector2d>& pts, std::optional<double> heading, bool twins_equal, bool searching) {
  const std::vector<Eigen::Vector2d> fit_pts = subsample(pts, p_.alt_points);
  const auto& pool = alt_.search(map_, fit_pts, heading, searching ? p_.alt.screened : p_.alt_tracking_restarts);
  // The current estimate's score on the same points: a proposal must beat it to enter.
  double current = 1.0;
  for (const auto& h : set_)
    if (static_cast<std::int64_t>(h.id) == best_id_) current = fit_score(map_, fit_pts, h.ukf.mean(), p_.alt.c);
  const int want = searching ? 2 : 1;
  int added = 0;
  for (const auto& cand : pool) {
    if (added >= want) break;
    if (heading && std::fabs(angle_diff(cand.pose.z(), *heading)) > p_.compass_gate) continue;
    bool known = false;
    for (const auto& h : set_)
      known = known || same_basin(cand.pose, h.ukf.mean(), p_.set.merge_xy, p_.set.merge_theta) ||
              (twins_equal && same_basin(cand.pose, twin(h.ukf.mean()), p_.set.merge_xy, p_.set.merge_theta));
    if (known) continue;
    if (!searching && !(cand.score < current - p_.alt_margin)) break;  // the pool is best first
    Hypothesis h;
    h.ukf.reset(Pose2(cand.pose.x(), cand.pose.y(), cand.pose.z()),
                Eigen::Vector3d(p_.new_sd_xy * p_.new_sd_xy, p_.new_sd_xy * p_.new_sd_xy, p_.new_sd_theta * p_.new_sd_theta).asDiagonal());
    if (p_.compass_sigma > 0) h.ukf.start_bias(p_.compass_bias_sd * p_.compass_bias_sd);
    // Half credit for the frame it was fitted to: one frame alone does not make a pose valid, and a
    // pose that explains fewer points than valid_min / 0.5 of them starts below what it can reach.
    h.validity = 0.5 * inlier_share(cand.pose);
    h.inliers = 2.0 * h.validity;
    h.id = next_id_++;
    // Replacement: when full, the least valid hypothesis that is not the current estimate goes.
    if (static_cast<int>(set_.size()) >= p_.set.max_hypotheses) {
      int worst = -1;
      for (std::size_t i = 0; i < set_.size(); ++i) {
        if (static_cast<std::int64_t>(set_[i].id) == best_id_ && set_.size() > 1) continue;
        if (worst < 0 || set_[i].validity < set_[static_cast<std::size_t>(worst)].validity) worst = static_cast<int>(i);
      }
      set_[static_cast<std::size_t>(worst)] = h;
    } else {
      set_.push_back(h);
    }
    ++added;
    ++proposals_;
  }
}

Estimate UkfMhLocalizer::update(const Observations& obs, const Odometry& odo, std::optional<double> heading) {
  const double dt = last_t_ ? obs.t - *last_t_ : 0.0;
  history_.push_back({last_t_.value_or(obs.t), obs.t, odo.delta});
  while (!history_.empty() && history_.front().t1 < obs.t - p_.latency - 1.0) history_.pop_front();
  last_t_ = obs.t;
  const double bias_q = p_.compass_bias_walk * p_.compass_bias_walk * std::max(dt, 0.0);
  for (auto& h : set_) {
    h.ukf.predict(odo.delta, motion_covariance(odo.delta, h.ukf.mean().z(), p_.motion), bias_q);
    h.age += dt;
    // The compass as a measurement of theta + bias; a hypothesis it contradicts (the twin, a wrong
    // search result) is left to the gate, which takes its validity, rather than turned by it.
    if (heading && p_.compass_sigma > 0 && std::fabs(angle_diff(h.ukf.mean().z(), *heading)) <= p_.compass_gate)
      h.ukf.fuse_heading(*heading, p_.compass_sigma * p_.compass_sigma);
  }
  alt_.move(odo.delta);
  // Twins: without a compass and without goal colours nothing tells a pose from its point mirror.
  bool goal_colours = false;
  for (const auto& g : field_.goals) goal_colours = goal_colours || g.colour != "white";
  const bool twins_equal = !heading && !goal_colours;

  prepare_points(subsample(obs.line_points, p_.max_points), obs.t);
  const std::vector<Eigen::Vector2d>& pts = frame_;
  const bool vision = obs.camera_ok && static_cast<int>(pts.size()) >= p_.min_points;
  if (vision) {
    for (auto& h : set_) sensor_update(h, pts, heading, obs, dt);
    merge(set_, p_.set, twins_equal, best_id_, p_.hysteresis);
    prune(set_, p_.set);
    bool any_valid = false;
    for (const auto& h : set_) any_valid = any_valid || h.validity >= p_.valid_min;
    if (!any_valid || obs.t - last_search_t_ >= p_.alt_period) {
      search(pts, heading, twins_equal, !any_valid);
      last_search_t_ = obs.t;
    }
  }

  int current = -1;
  for (std::size_t i = 0; i < set_.size(); ++i)
    if (static_cast<std::int64_t>(set_[i].id) == best_id_) current = static_cast<int>(i);
  const int b = best(set_, current, p_.hysteresis);
  Estimate e;
  e.extra["hypotheses"] = static_cast<double>(set_.size());
  e.extra["points"] = static_cast<double>(pts.size());
  e.extra["proposals"] = proposals_;
  e.extra["twin_ambiguous"] = twins_equal ? 1.0 : 0.0;
  if (b < 0) {
    e.mode = LocalizerMode::kGlobal;
    e.match_error = 1.0;
    e.extra["validity"] = 0.0;
    was_valid_ = false;
    return e;
  }
  const Hypothesis& h = set_[static_cast<std::size_t>(b)];
  best_id_ = h.id;
  e.pose = h.ukf.pose();
  e.covariance = h.ukf.covariance();
  e.valid = h.validity >= p_.valid_min;
  e.match_error = 1.0 - h.inliers;
  e.extra["validity"] = h.validity;
  if (!e.valid) e.mode = LocalizerMode::kGlobal;
  else if (!was_valid_) e.mode = LocalizerMode::kConverged;
  else e.mode = vision ? LocalizerMode::kTracking : LocalizerMode::kCoasting;
  was_valid_ = e.valid;
  return e;
}

DebugView UkfMhLocalizer::debug_view(std::size_t max_particles) const {
  DebugView v;
  for (std::size_t i = 0; i < set_.size() && i < max_particles; ++i) {
    const auto& q = set_[i].ukf.mean();
    v.particles.push_back({q.x(), q.y(), q.z(), set_[i].validity});
  }
  for (const auto& c : alt_.pool()) v.points.emplace_back(c.pose.x(), c.pose.y());
  return v;
}

}  // namespace omniloc::modern
