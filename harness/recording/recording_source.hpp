#pragma once
// A recording as a run's frame source (docs/recording.md): the frames a live run would have
// simulated and perceived, read back so any localizer runs on them without simulating or rendering.
#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "core/json_reader.hpp"
#include "harness/frame_source.hpp"
#include "harness/recording/format/header.hpp"

namespace omniloc::harness {

class FramesReader;


/// Frames read back from a recording, one at a time as the run asks for them (harness/recording/frames_reader.hpp:
/// memory flat in the recording's length, every check of docs/recording.md section 7). A damaged
/// file is found while reading: next() throws ConfigError and the run writes nothing. Images are read
/// one frame at a time.
class RecordingSource : public FrameSource {
 public:
  explicit RecordingSource(RecordingHeader header);
  ~RecordingSource() override;
  std::optional<FrameData> next() override;
  Json client_camera(int robot) const override;
  bool detects_blobs() const override;
  bool has_images() const override { return header_.images; }
  Json render_device() const override { return header_.render; }
  bool has_ground_truth() const override { return header_.ground_truth; }
  const RecordingHeader& header() const { return header_; }
  /// Lines the fast path parsed and lines the strict reader parsed (harness/recording/frames_reader.hpp).
  long long fast_lines() const;
  long long strict_lines() const;

 private:
  void read_timing();
  RecordingHeader header_;
  std::unique_ptr<FramesReader> reader_;
  std::map<std::pair<long long, int>, std::pair<double, double>> timing_;  ///< (k, robot) -> (render_ms, vision_ms)
};

}  // namespace omniloc::harness
