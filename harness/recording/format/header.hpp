#pragma once
// The recording format (docs/recording.md, format "omniloc-recording/1"): what a recording folder
// holds and what its recording.json says. The bottom of harness/recording/: it knows the format's
// words and limits, not how frames are simulated, written or replayed.
//
// A recording is a folder: recording.json (what was recorded: scenario, field, camera per robot,
// frame count, the SHA-256 of the frames), frames.jsonl.gz (one JSON object a camera frame, written
// and read by harness/recording/format/frame_codec.hpp) and, when recorded with images,
// images/r<robot>_<k>.png (lossless); timing.csv keeps what rendering cost.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "core/pose2.hpp"

namespace omniloc::harness {

/// The format this build writes and reads.
inline constexpr const char* kRecordingFormat = "omniloc-recording/1";
/// The frames file this build writes (readers take "frames.jsonl" too: recording.json "frames_file").
inline constexpr const char* kFramesFile = "frames.jsonl.gz";

/// The image of robot `robot` at frame `k`, relative to the recording folder ("images/r1_000042.png").
std::string image_name(int robot, long long k);

/// One robot of a recording's header.
struct RecordedRobot {
  int id = 0;
  std::optional<Pose2> start;  ///< the true start pose (tracking localizers get it), when known
  Json camera;                 ///< olp/1 hello.camera of this robot ({} without a camera)
  bool blobs = false;
};

/// What recording.json says. Read strictly: a file that is not a recording, a future format, a
/// missing or wrong key is a ConfigError naming the file and the JSON path.
struct RecordingHeader {
  std::string dir;          ///< the recording folder
  std::string format;
  Json omniloc;             ///< the build that wrote it, as given: anything in other writers' recordings
  std::string name;         ///< scenario name
  std::uint64_t seed = 0;
  Json scenario;            ///< the scenario as given (localizer included), null in a log not made by omniloc
  std::string scenario_source;
  Json field;               ///< the field as a scenario's "field" holds it: a preset name or a field object
  Json field_markings;      ///< olp/1 hello.field (the markings), when written
  std::string field_fingerprint;  ///< omniloc's Field::fingerprint(), empty when not known
  double camera_rate_hz = 30.0;
  double duration_s = 0.0;
  long long frames = 0;
  std::vector<RecordedRobot> robots;
  bool ground_truth = true;
  bool images = false;
  Json render;              ///< the renderer, null when none
  std::string frames_sha256;  ///< of the JSON lines (uncompressed)
  std::string frames_file = "frames.jsonl";

  static RecordingHeader read(const std::string& dir);
};

/// The omniloc version that wrote a recording, for a replay's provenance: the header's `omniloc`
/// block gives it as a string `version`; other writers may put anything there (docs/recording.md):
/// an object without a string version reads "unknown", anything else "not omniloc".
std::string recorded_with(const RecordingHeader& header);

}  // namespace omniloc::harness
