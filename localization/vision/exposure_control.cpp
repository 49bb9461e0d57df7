#include "localization/vision/exposure_control.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace omniloc {

const ParamList<ExposureParams>& ExposureParams::params() {
  using P = ExposureParams;
  static const ParamList<P> list = {
      bool_param("enabled", &P::enabled, "run paper 002's entropy auto-adjustment of exposure and gain"),
      positive_param("a", &P::a, 100.0, "ms per gain unit", "the search line exposure_ms = a * gain + b (paper 002)"),
      number_param("b", &P::b, -100.0, 100.0, "ms", "the search line's offset"),
      positive_param("change_threshold", &P::change_threshold, 255.0, "grey levels", "body brightness change against the saved value that starts a search"),
      integer_param("confirm_frames", &P::confirm_frames, 1, 1000, "frames in a row over the threshold before a search (noise, passing shadows)"),
      number_param("coarse_ratio", &P::coarse_ratio, 1.01, 4.0, "", "coarse phase: each probe multiplies (or divides) the gain by this"),
      integer_param("patience", &P::patience, 1, 20, "coarse phase: worse probes in a row before a direction is given up"),
      positive_param("min_step", &P::min_step, 100.0, "gain units", "fine phase (additive, halving) ends below this step"),
      integer_param("max_steps", &P::max_steps, 1, 1000, "hard bound on settings tried per search (reported when hit)"),
      number_param("settle_s", &P::settle_s, 0.0, 10.0, "s", "time a new setting needs before its frame counts (paper 002: about 40 ms)"),
      bool_param("search_at_start", &P::search_at_start, "also search on the first frame (the robot adjusts once when it starts)"),
  };
  return list;
}

ExposureParams ExposureParams::from_json(JsonReader& r) {
  ExposureParams p;
  read_params(r, p, params());
  return p;
}

ExposureController::ExposureController(const ExposureParams& p, const CameraSettings& initial) : p_(p), cur_(initial) {}

CameraSettings ExposureController::on_line(double g, std::vector<std::string>* warnings) const {
  CameraSettings s;
  const double g_clamped = std::clamp(g, p_.gain_min, p_.gain_max);
  s.gain = g_clamped;
  s.exposure_ms = p_.a * g_clamped + p_.b;
  const double e_clamped = std::clamp(s.exposure_ms, p_.exposure_min, p_.exposure_max);
  if (warnings && (g_clamped != g || e_clamped != s.exposure_ms)) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "exposure search left the camera's range (gain %.2f, exposure %.2f ms): clamped to gain %.2f, exposure %.2f ms", g,
                  p_.a * g + p_.b, g_clamped, e_clamped);
    warnings->push_back(buf);
  }
  s.exposure_ms = e_clamped;
  return s;
}

void ExposureController::start(double t, double change, double entropy) {
  state_ = State::Searching;
  ++searches_;
  steps_ = 0;
  best_g_ = cur_.gain;
  best_h_ = entropy;
  step_ = p_.min_step;
  dir_ = change > 0 ? -1 : 1;  // brighter than saved: less exposure and gain first
  tried_other_ = false;
  coarse_ = true;
  flipped_ = improved_ = false;
  fails_ = 0;
  last_g_ = best_g_;
  path_.assign(1, {best_g_, best_h_});
  settled_at_ = t;
}

void ExposureController::fail() {
  if (!tried_other_) {
    dir_ = -dir_;  // try the other side at the same step
    tried_other_ = true;
  } else {
    step_ *= 0.5;  // bracketed: refine around the best, both sides again
    tried_other_ = false;
  }
}

void ExposureController::propose(double t, double g, ExposureDecision& d) {
  std::vector<std::string> w;
  const CameraSettings s = on_line(g, &w);
  cur_ = s;
  ++steps_;
  settled_at_ = t + p_.settle_s;
  d.warnings.insert(d.warnings.end(), w.begin(), w.end());
}

ExposureDecision ExposureController::update(double t, double brightness, double entropy) {
  ExposureDecision d;
  const bool first = first_;
  first_ = false;
  if (!p_.enabled) {
    d.settings = cur_;
    return d;
  }
  if (state_ == State::Idle) {
    watch(t, brightness, entropy, first, d);
    return d;
  }
  // Searching: frames taken before the last setting settled do not count.
  d.searching = true;
  if (t + 1e-9 < settled_at_) {
    d.settings = cur_;
    return d;
  }
  measure_probe(brightness, entropy);
  skip_clamped_probes(d);
  if (step_ < p_.min_step || steps_ >= p_.max_steps) {
    end_search(t, d);
    return d;
  }
  propose(t, next_probe(), d);
  d.settings = cur_;
  return d;
}

void ExposureController::watch(double t, double brightness, double entropy, bool first, ExposureDecision& d) {
  if (first && p_.search_at_start) {
    start(t, 0.0, entropy);
    d.event = "search_start (first frame)";
    propose(t, next_probe(), d);
    d.settings = cur_;
    d.searching = true;
    return;
  }
  if (saved_brightness_ < 0) {
    save_settled_brightness(t, brightness, d);
    return;
  }
  watch_brightness(t, brightness, d);
}

void ExposureController::save_settled_brightness(double t, double brightness, ExposureDecision& d) {
  if (t + 1e-9 < settled_at_) {  // the final setting has not settled yet
    d.settings = cur_;
    return;
  }
  saved_brightness_ = brightness;
  // The light changed while the search ran (lamps warming up over a second): the entropies it
  // compared were taken under different light, and the chosen setting was measured under light
  // that is gone. The body at the chosen setting must look as it did when that setting was
  // measured; otherwise search again now (the normal trigger compares later frames with this
  // frame, so it would never fire, e.g. with a body clipped at 255 in the returned light).
  const double measured = check_brightness_;
  check_brightness_ = -1.0;
  if (measured >= 0 && std::fabs(brightness - measured) > p_.change_threshold) {
    d.settings = cur_;
    d.searching = true;
    char buf[160];
    std::snprintf(buf, sizeof buf, "search_start (light changed during the search: body brightness %.1f, %.1f when the setting was measured)",
                  brightness, measured);
    d.event = buf;
    start(t, brightness - measured, -1.0);
    return;
  }
  d.settings = cur_;
}

void ExposureController::watch_brightness(double t, double brightness, ExposureDecision& d) {
  const double change = brightness - saved_brightness_;
  over_ = std::fabs(change) > p_.change_threshold ? over_ + 1 : 0;
  if (over_ >= p_.confirm_frames) {
    over_ = 0;
    d.settings = cur_;
    d.searching = true;
    char buf[120];
    std::snprintf(buf, sizeof buf, "search_start (body brightness %.1f, saved %.1f)", brightness, saved_brightness_);
    d.event = buf;
    // The entropy of this frame is not known yet (not computed while idle): the first probe is the
    // current setting itself, measured on the next frame.
    start(t, change, -1.0);
    return;
  }
  d.settings = cur_;
}

void ExposureController::measure_probe(double brightness, double entropy) {
  const double g = cur_.gain;
  if (best_h_ < 0) {  // the starting setting, measured on this frame
    best_h_ = entropy;
    best_brightness_ = brightness;
    path_.assign(1, {g, entropy});
    return;
  }
  path_.push_back({g, entropy});
  const bool better = entropy > best_h_;
  if (better) {
    best_h_ = entropy;
    best_g_ = g;
    best_brightness_ = brightness;
  }
  if (coarse_) {
    // Coarse phase: geometric steps in one direction; a plateau or a local dip (clipping makes the
    // curve step-shaped) is crossed by allowing `patience` worse probes before giving up.
    if (better) {
      improved_ = true;
      fails_ = 0;
    } else {
      ++fails_;
    }
    last_g_ = g;
    if (fails_ >= p_.patience) end_coarse_direction();
  } else if (better) {
    tried_other_ = true;  // the other side is where we came from, known to be worse
  } else {
    fail();
  }
}

void ExposureController::skip_clamped_probes(ExposureDecision& d) {
  // Probes that the camera's range clamps onto a measured setting are skipped (with a warning).
  for (int guard = 0; guard < 8 && (coarse_ || step_ >= p_.min_step); ++guard) {
    const double next = on_line(next_probe()).gain;
    if (next != (coarse_ ? last_g_ : best_g_)) break;
    d.warnings.push_back("exposure search reached the camera's range limit at gain " + std::to_string(next));
    if (coarse_) end_coarse_direction();
    else fail();
  }
}

void ExposureController::end_search(double t, ExposureDecision& d) {
  if (steps_ >= p_.max_steps) {
    char buf[120];
    std::snprintf(buf, sizeof buf, "exposure search stopped after the maximum of %d settings", p_.max_steps);
    d.warnings.push_back(buf);
  }
  cur_ = on_line(best_g_);
  state_ = State::Idle;
  saved_brightness_ = -1.0;  // re-measured on the next frame, taken with the final setting
  check_brightness_ = best_brightness_;
  settled_at_ = t + p_.settle_s;
  char buf[160];
  std::snprintf(buf, sizeof buf, "search_end (gain %.2f, exposure %.2f ms, entropy %.3f, %d settings tried)", cur_.gain, cur_.exposure_ms, best_h_,
                steps_);
  d.event = buf;
  d.settings = cur_;
  d.searching = false;
}

double ExposureController::next_probe() const {
  if (coarse_) return dir_ > 0 ? last_g_ * p_.coarse_ratio : last_g_ / p_.coarse_ratio;
  return best_g_ + dir_ * step_;
}

void ExposureController::end_coarse_direction() {
  fails_ = 0;
  if (!improved_ && !flipped_) {  // nothing better this way: search the other way from the start
    flipped_ = true;
    dir_ = -dir_;
    last_g_ = best_g_;
    return;
  }
  // Fine phase around the best: steps of half a coarse step, both sides, halving.
  coarse_ = false;
  step_ = std::max(p_.min_step, 0.5 * best_g_ * (p_.coarse_ratio - 1.0));
  tried_other_ = false;
}

}  // namespace omniloc
