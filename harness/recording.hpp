#pragma once
// Recordings (docs/recording.md, format "omniloc-recording/1"): everything the localizers of a
// scenario's localized robots are given, frame by frame, with the truth and events scoring needs,
// so any localizer can be run on the same frames later without simulating or rendering them again.
//
// A recording is a folder: recording.json (what was recorded: scenario, field, camera per robot,
// frame count, the SHA-256 of the frames), frames.jsonl.gz (one JSON object a camera frame) and, when
// recorded with images, images/r<robot>_<k>.png (lossless); timing.csv keeps what rendering cost. It is written like a run folder: staged
// and renamed into place at the end, so an interrupted recording leaves nothing that looks whole.
#include <cstdint>
#include <map>
#include <utility>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "harness/frame_source.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

/// The format this build writes and reads.
inline constexpr const char* kRecordingFormat = "omniloc-recording/1";
/// The frames file this build writes (readers take "frames.jsonl" too: recording.json "frames_file").
inline constexpr const char* kFramesFile = "frames.jsonl.gz";

struct RecordOptions {
  std::optional<std::uint64_t> seed;  ///< overrides the scenario's seed
  std::string out_dir;                ///< default: results/recordings/<scenario>/<seed>
  bool images = false;                ///< also write every frame's image (PNG, lossless)
  std::ostream* log = nullptr;        ///< progress (null: silent)
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

class FramesReader;

/// Frames read back from a recording, one at a time as the run asks for them (harness/frames_reader.hpp:
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
  /// Lines the fast path parsed and lines the strict reader parsed (harness/frames_reader.hpp).
  long long fast_lines() const;
  long long strict_lines() const;

 private:
  void read_timing();
  RecordingHeader header_;
  std::unique_ptr<FramesReader> reader_;
  std::map<std::pair<long long, int>, std::pair<double, double>> timing_;  ///< (k, robot) -> (render_ms, vision_ms)
};

/// JSON of one frame as frames.jsonl holds it, and back (`at`: where, for errors).
Json frame_to_json(const FrameData& f);
/// `truth`: the frames carry the true pose ("truth"; recording.json "ground_truth").
FrameData frame_from_json(const Json& j, const std::string& at, const std::vector<RecordedRobot>& robots, bool truth = true);

/// The scenario a replay runs: the recorded one with `localizer` in place of its own (or, for a log
/// not made by omniloc, one built from the header). Checks that the robots and field agree. Errors in
/// the recorded scenario name the recording; errors in the localizer (LocalizerError) its own path.
Scenario replay_scenario(const RecordingHeader& header, const LocalizerSpec& localizer);

}  // namespace omniloc::harness
