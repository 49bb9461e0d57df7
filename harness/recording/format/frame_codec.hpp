#pragma once
// One frame of frames.jsonl (docs/recording.md section 4) and back: the recording format's frame
// codec. frame_from_json is the strict reader every frame a replay reads must pass (the fast path of
// harness/recording/frames_reader.cpp accepts exactly what it accepts, or hands the line to it).
#include <string>
#include <vector>

#include "core/json_reader.hpp"
#include "harness/frame_data.hpp"
#include "harness/recording/format/header.hpp"

namespace omniloc::harness {

/// JSON of one frame as frames.jsonl holds it, and back (`at`: where, for errors).
Json frame_to_json(const FrameData& f);
/// `truth`: the frames carry the true pose ("truth"; recording.json "ground_truth").
FrameData frame_from_json(const Json& j, const std::string& at, const std::vector<RecordedRobot>& robots, bool truth = true);

}  // namespace omniloc::harness
