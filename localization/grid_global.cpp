#include "localization/grid_global.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"

namespace omniloc {

const ParamList<GridGlobalParams>& GridGlobalParams::params() {
  using P = GridGlobalParams;
  static const ParamList<P> list = {
      number_param("spacing", &P::spacing, 0.1, 10.0, "m", "between grid samples (paper 000: 1 m)"),
      number_param("outside", &P::outside, 0.0, 5.0, "m", "the grid reaches this far beyond the outer lines (paper 000: 21 x 15 = 315 samples)"),
      number_param("shift", &P::shift, 0.0, 5.0, "m", "(x, y) shift of the grid between passes (paper 000; NuBot: 0, 35, 70 cm)"),
      integer_param("passes", &P::passes, 1, 20, "grid passes (paper 000: 3)"),
      integer_param("candidates", &P::candidates, 1, 100, "best samples refined by RPROP (paper 000: 5)"),
      positive_param("c_grid", &P::c_grid, 20.0, "m", "error scale of E_k on the grid (paper 000: c = 255 cm)"),
      integer_param("grid_points", &P::grid_points, 3, 10000, "line points (evenly subsampled) used for E_k"),
      integer_param("refine_iterations", &P::refine_iterations, 1, 1000, "at most this many RPROP iterations per candidate (paper 000: converges in about 10)"),
      positive_param("refine_c_start", &P::refine_c_start, 20.0, "m", "continuation of c from here down to matching.c while refining"),
      positive_param("accept_error", &P::accept_error, 1.0, "", "mean e(d) at matching.c under which a candidate is accepted at once"),
      number_param("min_separation", &P::min_separation, 0.0, 20.0, "m", "the candidates are distinct samples at least this far apart"),
      bool_param("record_traces", &P::record_traces, "keep each candidate's error per RPROP iteration (figures; costs time)"),
      positive_param("good_deviation", &P::good_deviation, 5.0, "m", "MTi drift correction: median point deviation under which a frame counts as good"),
      integer_param("drift_frames", &P::drift_frames, 1, 100000, "MTi drift correction: good frames averaged per correction"),
      number_param("drift_gain", &P::drift_gain, 0.0, 1.0, "", "MTi drift correction: fraction of the measured offset applied"),
  };
  return list;
}

Json GridGlobalParams::schema() {
  Json s = params_schema(params());
  s.update(params_schema(DetectionParams::params()));
  s["matching"] = {{"type", "object"}, {"description", "the matching tracker after the fix"}, {"properties", MatchingParams::schema()}, {"additionalProperties", false}};
  return s;
}

GridGlobalParams GridGlobalParams::from_json(JsonReader& r) {
  GridGlobalParams p;
  read_params(r, p, params());
  if (auto m = r.object("matching")) {
    p.matching = MatchingParams::from_json(*m);
    m->finish();
  }
  p.detection = DetectionParams::from_json(r);
  return p;
}

GridSearchRecord grid_search(const Field& field, const FieldMap& map, const std::vector<Eigen::Vector2d>& points, double heading,
                             const GridGlobalParams& p) {
  GridSearchRecord rec;
  rec.heading = heading;
  const auto grid_pts = subsample(points, p.grid_points);
  const auto match_pts = subsample(points, p.matching.max_points);
  const double x_lo = -0.5 * field.length - p.outside, y_lo = -0.5 * field.width - p.outside;
  const int nx = static_cast<int>(std::floor((field.length + 2 * p.outside) / p.spacing + 1e-9)) + 1;
  const int ny = static_cast<int>(std::floor((field.width + 2 * p.outside) / p.spacing + 1e-9)) + 1;
  // The points rotated once into the world orientation and scaled to distance-map cells: E_k then
  // needs only a translation per sample (the table a local, so its fields stay in registers).
  const FieldMap::Table t = map.table();
  const double c = std::cos(heading), s = std::sin(heading), c2 = p.c_grid * p.c_grid;
  std::vector<Eigen::Vector2d> rotated;
  rotated.reserve(grid_pts.size());
  for (const auto& o : grid_pts) rotated.emplace_back((c * o.x() - s * o.y()) * t.inv_cell, (s * o.x() + c * o.y()) * t.inv_cell);
  MatchingParams refine = p.matching;
  refine.c_start = std::max(refine.c, p.refine_c_start);

  for (int pass = 0; pass < p.passes; ++pass) {
    const double off = pass * p.shift;
    const std::size_t first = rec.samples.size();
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        GridSearchRecord::Sample smp{x_lo + i * p.spacing + off, y_lo + j * p.spacing + off, 0.0, pass};
        double e = 0;
        const double px = t.cells_x(smp.x), py = t.cells_y(smp.y);
        for (const auto& w : rotated) {
          const double d = t.at_cells<false>(px + w.x(), py + w.y()).d;
          e += 1.0 - c2 / (c2 + d * d);
        }
        smp.error = rotated.empty() ? 1.0 : e / static_cast<double>(rotated.size());
        rec.samples.push_back(smp);
      }
    // The best samples of this pass, distinct places (neighbours of one minimum would refine to the same pose).
    std::vector<std::size_t> order(rec.samples.size() - first);
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = first + k;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return rec.samples[a].error < rec.samples[b].error; });
    std::vector<std::size_t> best;
    for (std::size_t k : order) {
      if (static_cast<int>(best.size()) >= p.candidates) break;
      bool far = true;
      for (std::size_t b : best) far = far && std::hypot(rec.samples[k].x - rec.samples[b].x, rec.samples[k].y - rec.samples[b].y) >= p.min_separation - 1e-9;
      if (far) best.push_back(k);
    }
    for (std::size_t k : best) {
      GridSearchRecord::Candidate cand;
      cand.pass = pass;
      cand.start = Pose2(rec.samples[k].x, rec.samples[k].y, heading);
      const MatchResult m = rprop_match(map, match_pts, cand.start, refine, p.refine_iterations, heading, p.record_traces ? &cand.trace : nullptr);
      cand.result = m.pose;
      cand.error = m.error;
      rec.candidates.push_back(std::move(cand));
    }
    rec.passes = pass + 1;
    int chosen = -1;
    for (std::size_t k = 0; k < rec.candidates.size(); ++k)
      if (chosen < 0 || rec.candidates[k].error < rec.candidates[static_cast<std::size_t>(chosen)].error) chosen = static_cast<int>(k);
    rec.chosen = chosen;
    rec.accepted = chosen >= 0 && rec.candidates[static_cast<std::size_t>(chosen)].error < p.accept_error;
    if (rec.accepted) break;
  }
  return rec;
}

GridGlobalLocalizer::GridGlobalLocalizer(const Field& field, const GridGlobalParams& p, const std::string& cache_dir)
    : p_(p), field_(field), tracker_(field, p.matching, cache_dir), detector_(p.detection) {}

void GridGlobalLocalizer::reset(const std::optional<Pose2>& start) {
  tracking_ = false;
  offset_ = 0.0;
  good_frames_ = 0;
  detector_.reset();
  if (start) {
    tracker_.reset(start);
    tracking_ = true;
  }
}

Estimate GridGlobalLocalizer::update(const Observations& obs, const Odometry& odo, std::optional<double> raw_heading) {
  std::optional<double> heading;
  if (raw_heading) heading = wrap_angle(*raw_heading + offset_);
  Estimate e;
  if (!tracking_) {
    const auto pts = subsample(obs.line_points, p_.matching.max_points);
    e.mode = LocalizerMode::kGlobal;
    e.valid = false;
    if (obs.camera_ok && static_cast<int>(pts.size()) >= p_.matching.min_points) {
      // Paper 000 needs the MTi; without a heading, search eight headings (eight times the work).
      std::vector<double> headings;
      if (heading) headings.push_back(*heading);
      else
        for (int k = 0; k < 8; ++k) headings.push_back(-kPi + k * kPi / 4);
      std::optional<GridSearchRecord> best;
      for (double h : headings) {
        GridSearchRecord r = grid_search(field_, tracker_.map(), obs.line_points, h, p_);
        if (!best || r.candidates[static_cast<std::size_t>(r.chosen)].error < best->candidates[static_cast<std::size_t>(best->chosen)].error)
          best = std::move(r);
      }
      ++searches_;
      const auto& ch = best->candidates[static_cast<std::size_t>(best->chosen)];
      tracker_.reset(ch.result);
      tracking_ = true;
      detector_.reset();
      good_frames_ = 0;
      e.pose = ch.result;
      e.valid = true;
      e.mode = best->accepted ? LocalizerMode::kConverged : LocalizerMode::kConvergedWeak;
      e.match_error = ch.error;
      e.extra["global_passes"] = best->passes;
      last_ = std::move(best);
    }
  } else {
    e = tracker_.track(obs, odo);
    if (e.mode == LocalizerMode::kTracking) {
      const auto pts = subsample(obs.line_points, p_.matching.max_points);
      const double dev = line_deviation(tracker_.map(), pts, e.pose, p_.detection.deviation_quantile);
      e.extra["deviation_m"] = dev;
      // MTi drift correction by the vision heading (paper 000), only for small disagreements. "Good"
      // is judged on the median: the detector's upper quartile of a correct pose is often above
      // good_deviation through the far points, and a drifting MTi must be corrected all the same.
      if (heading) {
        const double diff = angle_diff(e.pose.theta, *heading);
        good_frames_ = line_deviation(tracker_.map(), pts, e.pose, 0.5) < p_.good_deviation && std::fabs(diff) < p_.detection.heading_threshold ? good_frames_ + 1 : 0;
        if (good_frames_ >= p_.drift_frames) {
          offset_ = wrap_angle(offset_ + p_.drift_gain * diff);
          heading = wrap_angle(*raw_heading + offset_);
        }
      }
      if (detector_.update(dev, e.pose, heading)) {
        tracking_ = false;
        ++restarts_;
        e.valid = false;
        e.mode = LocalizerMode::kRestart;
      }
    }
  }
  e.extra["restarts"] = restarts_;
  e.extra["heading_offset"] = offset_;
  return e;
}

}  // namespace omniloc
