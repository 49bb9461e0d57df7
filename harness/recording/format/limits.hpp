#pragma once
// The physical limits of a recording's numbers (docs/recording.md section 7), one list for both
// readers of frames (harness/recording/format/frame_codec.cpp's strict one and harness/recording/frames_reader.cpp's fast path,
// which must accept exactly what the strict one accepts). A value outside them cannot come from a
// robot on a field omniloc accepts, and huge ones overflow a localizer's sums (a line point at
// -1e308 m became -inf cells in the distance map lookup).
#include <cstdint>

namespace omniloc::harness::recording_limits {

// Lengths, metres: the largest field omniloc reads is 22 x 14 m with 5 m margins, a 32 x 24 m floor
// (40 m diagonal); nothing on it, and no robot's step between two frames, is farther than 50 m.
inline constexpr double kMaxLength = 50.0;
// Angles, radians: need not be wrapped; 1000 rad (159 turns) keeps a double angle to 1e-13 rad.
inline constexpr double kMaxAngle = 1000.0;
// Times, seconds from the start of the recording: at most an hour, the longest scenario omniloc
// runs (its duration_s, and 720,000 frames at the highest camera rate, 200 Hz).
inline constexpr double kMaxTime = 3600.0;
inline constexpr long long kMaxFrames = 720000;
// Camera settings (frames.csv's columns only; the simulated camera's range is 1-60 ms and 1-60 gain
// units by default): exposure at most 10 s, longer than any frame a moving robot uses; gain at most 1000.
inline constexpr double kMaxExposureMs = 1e4;
inline constexpr double kMaxGain = 1e3;
// The largest frames file read, uncompressed (a frame with thousands of line points is about 100 kB).
inline constexpr std::uintmax_t kMaxFramesBytes = 8ULL << 30;

}  // namespace omniloc::harness::recording_limits
