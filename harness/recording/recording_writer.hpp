#pragma once
// Writing a recording (docs/recording.md): a scenario simulated and perceived, every frame its
// localizers would be given written in the recording format (harness/recording/format/). It is
// written like a run folder: staged and renamed into place at the end, so an interrupted recording
// leaves nothing that looks whole.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>

#include "harness/frame_data.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

struct RecordOptions {
  std::optional<std::uint64_t> seed;  ///< overrides the scenario's seed
  std::string out_dir;                ///< default: results/recordings/<scenario>/<seed>
  bool images = false;                ///< also write every frame's image (PNG, lossless)
  std::ostream* log = nullptr;        ///< progress (null: silent)
  /// Every frame as it is recorded (the bound cache's BoundPreparer, harness/bound_prepare.hpp).
  std::function<void(const FrameData&)> on_frame;
};

struct RecordResult {
  std::string out_dir;
  std::uint64_t seed = 0;
  long long frames = 0;
  std::size_t frames_bytes = 0;       ///< size of frames.jsonl.gz
  std::size_t frames_text_bytes = 0;  ///< size of the JSON lines it holds
  std::size_t image_bytes = 0;   ///< size of all images
};

/// Simulates and perceives `sc` (camera and vision always on, as for a localizer that needs vision)
/// and writes the recording. No localizer runs.
RecordResult record_scenario(const Scenario& sc, const RecordOptions& options);

}  // namespace omniloc::harness
