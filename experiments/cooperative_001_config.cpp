// Configuration of "cooperative_001" (both observation modes) and the set-up both modes share.
// See cooperative_001_config.hpp and docs/cooperative.md.
#include "experiments/cooperative_001_config.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/angles.hpp"
#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/localizer_registry.hpp"
#include "core/install_paths.hpp"

namespace omniloc::experiments {

using harness::localizer_info;

const char* to_string(CoopNoiseModel m) {
  switch (m) {
    case CoopNoiseModel::Cartesian: return "cartesian";
    case CoopNoiseModel::Polar: return "polar";
    case CoopNoiseModel::RobotPose: return "robot_pose";
  }
  return "unknown";
}

const char* to_string(CoopPoseSource s) { return s == CoopPoseSource::Matching ? "matching" : "noisy_truth"; }

// --- configuration --------------------------------------------------------------------------------------

namespace {

CoopNoiseModel noise_model_from(const std::string& s) {
  if (s == "cartesian") return CoopNoiseModel::Cartesian;
  if (s == "robot_pose") return CoopNoiseModel::RobotPose;
  return CoopNoiseModel::Polar;
}

Eigen::Vector2d point_in_field(JsonReader& r, const std::string& key, const Cooperative001Config& c) {
  const std::vector<double> v = r.numbers(key, std::nullopt, 2);
  if (v[0] < 0.0 || v[0] > c.field_length || v[1] < 0.0 || v[1] > c.field_width) {
    std::ostringstream e;
    e << "a point [x, y] in metres inside the field [0, " << c.field_length << "] x [0, " << c.field_width << "]";
    throw ConfigError(r.child_path(key), json_brief(*r.raw(key)), e.str());
  }
  return {v[0], v[1]};
}

CoopTrials read_trials(JsonReader& r, const CoopTrials& d) {
  CoopTrials t;
  t.path = static_cast<int>(r.integer("path", d.path, 1, 1000000));
  t.per_subset = static_cast<int>(r.integer("per_subset", d.per_subset, 1, 100000));
  t.tracking = static_cast<int>(r.integer("tracking", d.tracking, 1, 100000));
  t.growth_model = static_cast<int>(r.integer("growth_model", d.growth_model, 2, 1000000));
  r.finish();
  return t;
}

/// /robots: 1 to 10 positions [x, y] (m) inside the field of `c`.
std::vector<Eigen::Vector2d> read_robots(JsonReader& r, const Cooperative001Config& c) {
  const Json* robots = r.raw("robots", true);
  std::vector<Eigen::Vector2d> robots_out;
  constexpr std::size_t kMaxRobots = 10;  // the robot-count figure runs all 2^n - 1 subsets
  if (!robots->is_array() || robots->empty() || robots->size() > kMaxRobots)
    throw ConfigError("/robots", json_brief(*robots), "an array of 1 to 10 robot positions [x, y] in metres");
  for (std::size_t i = 0; i < robots->size(); ++i) {
    const Json& p = (*robots)[i];
    const std::string path = json_child("/robots", i);
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number() || !std::isfinite(p[0].get<double>()) ||
        !std::isfinite(p[1].get<double>()))
      throw ConfigError(path, json_brief(p), "a robot position [x, y]: two finite numbers in metres");
    const Eigen::Vector2d v(p[0].get<double>(), p[1].get<double>());
    if (v.x() < 0.0 || v.x() > c.field_length || v.y() < 0.0 || v.y() > c.field_width) {
      std::ostringstream e;
      e << "a robot position inside the field [0, " << c.field_length << "] x [0, " << c.field_width << "] m";
      throw ConfigError(path, json_brief(p), e.str());
    }
    robots_out.push_back(v);
  }
  return robots_out;
}

/// Strict parsing of the "rendered" object (`r` at /rendered); field size checked against `c`.
CoopRenderedConfig parse_coop_rendered(JsonReader& r, const Cooperative001Config& c) {
  CoopRenderedConfig g;
  r.allow("comment");
  {
    const Json* fj = r.raw("field", true);
    const std::string fp = r.child_path("field");
    if (!fj->is_object()) throw ConfigError(fp, json_brief(*fj), "a field object (docs/scenario.md, \"field\"), field frame");
    // The rendered field must be the field the experiment's coordinates live on: its size comes from
    // /field unless given, and must then agree.
    Json f = *fj;
    if (!f.contains("length")) f["length"] = c.field_length;
    if (!f.contains("width")) f["width"] = c.field_width;
    g.field = Field::from_json(f, fp);
    if (std::abs(g.field.length - c.field_length) > 1e-9)
      throw ConfigError(json_child(fp, "length"), json_brief(f["length"]), "the length of /field (" + std::to_string(c.field_length) + " m)");
    if (std::abs(g.field.width - c.field_width) > 1e-9)
      throw ConfigError(json_child(fp, "width"), json_brief(f["width"]), "the width of /field (" + std::to_string(c.field_width) + " m)");
  }
  if (const Json* cj = r.raw("camera")) g.camera = sim::CameraConfig::from_json(*cj, r.child_path("camera"));
  if (const Json* h = r.raw("headings_deg")) {
    const std::string hp = r.child_path("headings_deg");
    if (!h->is_array() || h->size() != c.robots.size())
      throw ConfigError(hp, json_brief(*h), "an array of " + std::to_string(c.robots.size()) + " robot headings in degrees (one per robot)");
    for (std::size_t i = 0; i < h->size(); ++i) {
      const Json& v = (*h)[i];
      if (!v.is_number() || !std::isfinite(v.get<double>()) || std::abs(v.get<double>()) > 360.0)
        throw ConfigError(json_child(hp, i), json_brief(v), "a heading in degrees in [-360, 360]");
      g.headings.push_back(v.get<double>() * kPi / 180.0);
    }
  }
  g.trials = static_cast<int>(r.integer("trials", 30, 1, 100000));
  g.quick_trials = static_cast<int>(r.integer("quick_trials", 1, 1, 100000));
  g.min_area_px = static_cast<int>(r.integer("min_area_px", 6, 1, 100000));
  g.ball_radius = r.positive("ball_radius", 0.11, 1.0);
  g.robot_radius = r.positive("robot_radius", 0.26, 2.0);
  g.robot_height = r.positive("robot_height", 0.8, 3.0);
  g.tracking_repeats = static_cast<int>(r.integer("tracking_repeats", 20, 0, 10000));
  if (auto s = r.object("self_localisation")) {
    s->allow("comment");
    g.pose_source = s->string("source", std::string("matching"), {"matching", "noisy_truth"}) == "matching" ? CoopPoseSource::Matching
                                                                                                            : CoopPoseSource::NoisyTruth;
    if (const Json* l = s->raw("localizer")) {
      const std::string lp = s->child_path("localizer");
      if (!l->is_object() || !l->contains("type") || !(*l)["type"].is_string())
        throw ConfigError(lp, json_brief(*l), "a localizer object {\"type\": ..., params}");
      (void)localizer_info((*l)["type"].get<std::string>(), json_child(lp, "type"));  // unknown types fail here, naming the path
      g.localizer = *l;
    }
    g.selfloc_frames = static_cast<int>(s->integer("frames", 15, 1, 10000));
    g.start_offset = s->number("start_offset", 0.3, 0.0, 5.0);
    g.start_heading_offset = s->number("start_heading_offset_deg", 10.0, 0.0, 180.0) * kPi / 180.0;
    g.pose_sigma = s->number("pose_sigma", 0.05, 0.0, 5.0);
    s->finish();
  }
  r.finish();
  const Eigen::Vector2d half(0.5 * c.field_length, 0.5 * c.field_width);
  for (std::size_t i = 0; i < c.robots.size(); ++i)
    if (!g.field.inside_floor(c.robots[i] - half, g.robot_radius))
      throw ConfigError(json_child("/robots", i), "robot " + std::to_string(i + 1),
                        "a robot whose footprint fits on the rendered field's floor (inside the walls)");
  return g;
}

}  // namespace

Cooperative001Config parse_cooperative_001(const Json& j) {
  Cooperative001Config c;
  JsonReader r(j, "");
  r.allow("comment");
  r.string("experiment", std::nullopt, {"cooperative_001"});
  c.description = r.string("description", std::string());

  if (auto f = r.object("field", true)) {
    f->allow("comment");
    c.field_length = f->positive("length", std::nullopt, 100.0);
    c.field_width = f->positive("width", std::nullopt, 100.0);
    f->finish();
  }

  c.robots = read_robots(r, c);

  if (auto b = r.object("ball", true)) {
    b->allow("comment");
    c.ball_start = point_in_field(*b, "start", c);
    c.ball_end = point_in_field(*b, "end", c);
    c.ball_step = b->positive("step", 0.05, 10.0);
    c.step_time = b->positive("step_time", 0.04, 10.0);
    if ((c.ball_end - c.ball_start).norm() < c.ball_step)
      throw ConfigError(b->child_path("end"), json_brief(*b->raw("end")), "an end point at least one step (" + std::to_string(c.ball_step) + " m) from the start");
    b->finish();
  }
  if (c.path_positions() > 100000) throw ConfigError("/ball/step", std::to_string(c.ball_step), "a step giving at most 100000 positions");

  if (auto n = r.object("noise", true)) {
    n->allow("comment");
    c.noise_model = noise_model_from(n->string("model", std::string("polar"), {"polar", "cartesian", "robot_pose"}));
    c.sigma = n->number("sigma", 0.192, 0.0, 10.0);
    if (n->has("reference_distance")) c.reference_distance = n->positive("reference_distance", std::nullopt, 100.0);
    n->finish();
  }

  if (auto n = r.object("network")) {
    n->allow("comment");
    c.network = sim::NetworkConfig::from_json(*n, c.network);
    n->finish();
  }
  sim::NetworkConfig lossy;
  lossy.latency = 0.1;
  lossy.loss = 0.2;
  c.lossy_network = lossy;
  if (auto n = r.object("lossy_network")) {
    n->allow("comment");
    c.lossy_network = sim::NetworkConfig::from_json(*n, lossy);
    n->finish();
  }
  c.fusion_deadline = r.number("fusion_deadline", 0.16, 0.0, 10.0);

  if (auto t = r.object("trials")) {
    t->allow("comment");
    c.trials = read_trials(*t, c.trials);
  }
  if (auto t = r.object("quick_trials")) {
    t->allow("comment");
    c.quick_trials = read_trials(*t, c.quick_trials);
  }
  if (auto t = r.object("tracking")) {
    t->allow("comment");
    c.accel_sigma = t->positive("accel_sigma", 5.0, 100.0);
    c.particles = static_cast<int>(t->integer("particles", 100, 2, 100000));
    c.tracking_threshold = t->number("threshold", 0.5, 0.0, 1.0);
    t->finish();
  }
  if (auto g = r.object("rendered")) c.rendered = parse_coop_rendered(*g, c);
  r.finish();
  return c;
}

Cooperative001Config load_cooperative_001(const std::string& file) {
  return parse_cooperative_001(read_json_strict(file, file));
}

std::string cooperative_001_default_file() { return (share_dir() / "scenarios/experiments/cooperative_001.json").string(); }

void validate_cooperative_001(const std::string& file) { (void)load_cooperative_001(file); }

int Cooperative001Config::path_positions() const {
  const double len = (ball_end - ball_start).norm();
  return static_cast<int>(std::floor(len / ball_step + 1e-9)) + 1;
}

Eigen::Vector2d Cooperative001Config::ball_at(double t) const {
  const Eigen::Vector2d dir = (ball_end - ball_start).normalized();
  return ball_start + dir * (ball_step / step_time) * t;
}

double Cooperative001Config::reference_distance_or_mean() const {
  if (reference_distance) return *reference_distance;
  double s = 0.0;
  const int n = path_positions();
  for (int k = 0; k < n; ++k)
    for (const auto& r : robots) s += (ball_at(k * step_time) - r).norm();
  return s / static_cast<double>(n * static_cast<int>(robots.size()));
}

// --- set-up shared by both modes ------------------------------------------------------------------------

Rng cooperative_trial_rng(std::uint64_t seed, const std::string& name, int t) {
  return Rng(splitmix64(derive_seed(seed, name) + splitmix64(static_cast<std::uint64_t>(t) + 1)));
}

std::unique_ptr<BallTracker> make_coop_tracker(const Cooperative001Config& c, const std::string& name, double obs_sigma,
                                               const Eigen::Vector2d& first) {
  CvModelConfig mc;
  mc.dt = c.step_time;
  mc.accel_sigma = c.accel_sigma;
  mc.obs_sigma = std::max(1e-3, obs_sigma);
  ParticleTrackerConfig pc;
  pc.particles = c.particles;
  pc.threshold = c.tracking_threshold;
  auto tracker = make_ball_tracker(name, mc, pc);
  const double ps = mc.obs_sigma, vs = 2.0;  // m, m/s
  tracker->init(Eigen::Vector4d(first.x(), first.y(), 0.0, 0.0), Eigen::Vector4d(ps * ps, ps * ps, vs * vs, vs * vs).asDiagonal());
  return tracker;
}

HoughBallConfig coop_hough_config(BallWeighting weighting) {
  HoughBallConfig h;
  h.weighting = weighting;
  return h;
}

const std::vector<std::string>& coop_trackers() {
  static const std::vector<std::string> list = {"kf", "pf", "fbpf", "mfbpf"};
  return list;
}

std::optional<Eigen::Vector2d> first_fix(const CoopFixSequence& z) {
  for (const auto& zz : z)
    if (zz) return *zz;
  return std::nullopt;
}

std::vector<double> coop_tracker_errors(const Cooperative001Config& c, const std::string& name, double obs_sigma, const Eigen::Vector2d& first,
                                        const CoopFixSequence& z, Rng& rng) {
  auto tracker = make_coop_tracker(c, name, obs_sigma, first);
  std::vector<double> e;
  for (int k = 0; k < c.path_positions(); ++k)
    e.push_back((tracker->step(z[static_cast<std::size_t>(k)], rng).state.head<2>() - c.ball_at(k * c.step_time)).norm());
  return e;
}

}  // namespace omniloc::experiments
