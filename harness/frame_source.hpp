#pragma once
// Where a run's camera frames come from: the seam between "what the robots see" and "who localizes".
// A FrameSource yields, frame by frame, everything the localizers of the localized robots are given
// (odometry, heading, the perception's observations) and what scoring needs (the true pose, contact),
// plus the lines the world and the perception add to events.jsonl. The live source simulates and
// perceives (harness/simulation, harness/perception); a recording source reads what a live source
// wrote (harness/recording/recording_source.hpp, docs/recording.md). The run loop (harness/runner.cpp) does not know
// which one it reads, so a replay writes the same run folder as the live run it was recorded from.
//
// Units: seconds, metres, radians; poses in the world frame, observations in the robot frame.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "core/messages.hpp"
#include "core/pose2.hpp"
#include "harness/frame_data.hpp"
#include "harness/perception.hpp"
#include "harness/scenario.hpp"
#include "harness/simulation.hpp"
#include "localization/localizer.hpp"

namespace omniloc::harness {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt after the last one.
  virtual std::optional<FrameData> next() = 0;
  /// hello.camera of olp/1 for `robot` (image size, mirror centre, calibration); {} without a camera.
  virtual Json client_camera(int robot) const = 0;
  /// Whether observations can carry blobs.
  virtual bool detects_blobs() const = 0;
  /// Whether frames carry the image (a recording made with --images, or a live camera).
  virtual bool has_images() const = 0;
  /// Provenance of the renderer (summary.json "omniloc"."render"), null when none.
  virtual Json render_device() const = 0;
  /// Whether frames carry the true pose (a real robot's log may not): without it nothing is scored.
  virtual bool has_ground_truth() const { return true; }
};

/// Simulation and perception of a scenario, frame by frame (the live run). With `camera` false the
/// perception renders nothing (localizers that need no vision), as NoPerception does.
class LiveSource : public FrameSource {
 public:
  LiveSource(const Scenario& sc, std::uint64_t seed, bool camera);
  ~LiveSource() override;
  std::optional<FrameData> next() override;
  Json client_camera(int robot) const override;
  bool detects_blobs() const override;
  bool has_images() const override { return camera_; }
  Json render_device() const override;
  const Perception& perception() const { return *perception_; }

 private:
  const Scenario& sc_;
  EventLog log_;  ///< the scenario's events as the Simulation applies them
  std::size_t log_read_ = 0;
  Simulation sim_;
  std::unique_ptr<Perception> perception_;
  bool camera_;
  long long k_ = 0, n_frames_ = 0;
};

/// The events.jsonl lines perception adds for one frame (warnings, camera control, pause / resume).
std::vector<std::string> perception_events(const PerceptionOutput& po, int robot, double t, bool was_paused);

}  // namespace omniloc::harness
