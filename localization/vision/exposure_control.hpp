#pragma once
// Camera auto-adjustment by image entropy (paper 002): exposure and gain move together along the
// line exposure = a * gain + b (paper: a = 1, b = 0, so 18 ms / 18 under normal light) and the
// setting with the most image entropy is searched for; entropy is single-peaked along that line.
// A search starts when the brightness of the robot's own body in the image centre differs from the
// value saved after the last adjustment (a lighting change, not a scene change), and it first steps
// the way that undoes the change (brighter -> lower). Every new setting takes effect on the next
// frame and costs the settle time (paper: about 40 ms); the robot stands while the search runs.
// The colour table is not relearned: it stays the one learned under normal light, as in the paper.
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "core/params.hpp"
#include "core/messages.hpp"

namespace omniloc {

struct ExposureParams {
  bool enabled = false;
  double a = 1.0, b = 0.0;          ///< exposure_ms = a * gain + b (paper 002)
  double exposure_min = 1.0, exposure_max = 60.0;  ///< ms, the camera's range (clamped, with a warning)
  double gain_min = 1.0, gain_max = 60.0;
  double change_threshold = 12.0;   ///< grey levels of body brightness against the saved value
  int confirm_frames = 2;           ///< that many frames in a row before a search (noise, passing shadows)
  double coarse_ratio = 1.25;       ///< coarse phase: each probe multiplies (or divides) the gain by this
  int patience = 2;                 ///< coarse phase: worse probes in a row before a direction is given up
  double min_step = 0.5;            ///< fine phase (additive, halving) ends below this step, gain units
  int max_steps = 24;               ///< hard bound on settings tried per search (reported when hit)
  double settle_s = 0.04;           ///< s a new setting needs before its frame counts (paper: ~40 ms)
  bool search_at_start = true;      ///< also search on the first frame (the robot adjusts once when it starts)
  static ExposureParams from_json(JsonReader& r);
  /// The JSON keys (scenario /vision/exposure_control); the camera ranges come from /camera.
  static const ParamList<ExposureParams>& params();
};

/// What the controller wants after one frame.
struct ExposureDecision {
  CameraSettings settings;          ///< for the next frame
  bool searching = false;           ///< the robot should stand still
  std::vector<std::string> warnings;
  std::optional<std::string> event; ///< "search_start", "search_end ..." for the run's events
};

class ExposureController {
 public:
  ExposureController(const ExposureParams& p, const CameraSettings& initial);
  /// Whether the next update needs the frame's entropy (computing it costs about a millisecond).
  bool wants_entropy() const { return state_ != State::Idle || (first_ && p_.search_at_start); }
  /// Whether a search is running, i.e. the next frame is taken at one of its trial settings.
  bool searching() const { return state_ == State::Searching; }
  /// One frame taken with `current()` at time t (s): its body brightness (0..255) and, if
  /// wants_entropy(), its entropy (nats).
  ExposureDecision update(double t, double body_brightness, double entropy);
  const CameraSettings& current() const { return cur_; }
  int searches() const { return searches_; }
  int steps_last_search() const { return steps_; }
  /// Gains tried in the last search, with their entropies (for the search-path pictures).
  const std::vector<std::pair<double, double>>& path() const { return path_; }
  /// Settings for gain g on the search line, clamped to the camera's range.
  CameraSettings on_line(double g, std::vector<std::string>* warnings = nullptr) const;

 private:
  enum class State { Idle, Searching };
  // The steps of update(). While idle: start a search on the first frame (search_at_start), keep
  // the settled body brightness (and search again when the light changed during the last search),
  // or watch it for a change. While searching: judge the probe measured on this frame, skip probes
  // the camera's range clamps onto a measured setting, end the search or propose the next probe.
  void watch(double t, double brightness, double entropy, bool first, ExposureDecision& d);
  void save_settled_brightness(double t, double brightness, ExposureDecision& d);
  void watch_brightness(double t, double brightness, ExposureDecision& d);
  void measure_probe(double brightness, double entropy);
  void skip_clamped_probes(ExposureDecision& d);
  void end_search(double t, ExposureDecision& d);
  void start(double t, double brightness_change, double entropy);
  void propose(double t, double g, ExposureDecision& d);
  void fail();
  double next_probe() const;
  void end_coarse_direction();
  ExposureParams p_;
  CameraSettings cur_;
  State state_ = State::Idle;
  bool first_ = true;
  double saved_brightness_ = -1.0;
  double best_brightness_ = -1.0;   // body brightness on the frame that measured the best setting
  double check_brightness_ = -1.0;  // after a search: that value, to compare with the first settled frame
  int over_ = 0, searches_ = 0, steps_ = 0;
  double best_g_ = 0, best_h_ = 0, step_ = 0, settled_at_ = 0;
  int dir_ = 1;
  bool tried_other_ = false;
  bool coarse_ = true, flipped_ = false, improved_ = false;
  int fails_ = 0;
  double last_g_ = 0;
  std::vector<std::pair<double, double>> path_;
};

}  // namespace omniloc
