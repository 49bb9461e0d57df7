#pragma once
// Reads a recording's frames file (frames.jsonl.gz or frames.jsonl, docs/recording.md section 4)
// one frame at a time, as the replay consumes them: memory stays flat in the recording's length and
// a replay runs at the speed of its localizer rather than of a JSON parser.
//
// Every check of the whole-file reader it replaced is kept, with the same messages: the SHA-256 of
// the JSON lines, whole lines, the frame count, the order of k and t, the type and range of every
// value (harness/recording/format/frame_codec.cpp frame_from_json), the gzip stream's integrity. What changes is *when*
// a damaged file is found: while reading, not before the first frame. A replay that meets one fails
// (exit 2) and writes nothing, and the error reported is the one the whole-file reader reported:
// the rest of the file is read first, so a cut or changed file (gzip, SHA-256) is named before the
// first bad line it shows.
//
// Speed: simdjson (libsimdjson-dev) parses each line and the values go straight into FrameData; a
// line that the fast path does not take exactly as frame_from_json would (an unknown key, events,
// blobs, a type or range error, a duplicate key, anything simdjson refuses) is read again by
// nlohmann's strict parser and frame_from_json, which either give the same FrameData or throw the
// message. docs/performance.md "Replay" gives the figures.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "harness/frame_data.hpp"

namespace omniloc::harness {

struct RecordingHeader;

class FramesReader {
 public:
  /// Opens `header.dir`/`header.frames_file`; throws ConfigError when it is missing or too large.
  explicit FramesReader(const RecordingHeader& header);
  ~FramesReader();
  FramesReader(const FramesReader&) = delete;
  FramesReader& operator=(const FramesReader&) = delete;
  /// The next frame, checked; nullopt after the last one, once the count and the SHA-256 agree with
  /// recording.json. Throws ConfigError naming the file, the line and the JSON path.
  std::optional<FrameData> next();
  /// Lines parsed by the fast path and by the strict fallback (for tests and benchmarks).
  long long fast_lines() const;
  long long strict_lines() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace omniloc::harness
