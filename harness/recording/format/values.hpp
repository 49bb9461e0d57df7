#pragma once
// The strict readers of a recording's values (recording.json and frames.jsonl, docs/recording.md
// section 7), shared by the header and the frame codec so both refuse a value with the same words:
// `at` names the file, line and JSON path; a value outside harness/recording/format/limits.hpp is
// a ConfigError.
#include <string>

#include "core/json_reader.hpp"
#include "core/pose2.hpp"

namespace omniloc::harness::recording_values {

[[noreturn]] void bad(const std::string& at, const Json& v, const std::string& expected);
/// o[key]; a ConfigError when it is absent.
const Json& member(const Json& o, const char* key, const std::string& at);
double finite(const Json& v, const std::string& at);
/// A finite number in [lo, hi] (`unit` for the message).
double within(const Json& v, const std::string& at, double lo, double hi, const char* unit);
/// Metres and radians within the limits.
double length(const Json& v, const std::string& at);
double angle(const Json& v, const std::string& at);
bool boolean(const Json& v, const std::string& at);
/// A pose or an odometry step: [x, y, theta], metres and radians, each within the limits.
Pose2 pose(const Json& v, const std::string& at);
/// A pose as the format writes it: [x, y, theta].
Json pose_json(const Pose2& p);

}  // namespace omniloc::harness::recording_values
