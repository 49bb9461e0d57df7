#include "harness/recording/recording_source.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/recording/frames_reader.hpp"
#include "harness/recording/png_reader.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;

RecordingSource::RecordingSource(RecordingHeader header) : header_(std::move(header)), reader_(std::make_unique<FramesReader>(header_)) {
  read_timing();
}

RecordingSource::~RecordingSource() = default;

// timing.csv (optional): the render and vision times the recording's frames cost, for the run's
// timing.csv. A line that does not parse is ignored: these are wall-clock figures, never results.
void RecordingSource::read_timing() {
  // Optional: anything but a readable file (a FIFO would block the read) is as if it were absent.
  const std::string file = (fs::path(header_.dir) / "timing.csv").string();
  if (!why_not_readable_file(file).empty()) return;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return;
  while (std::getline(in, line)) {
    long long k = 0;
    int robot = 0;
    double render = 0, vision = 0;
    if (std::sscanf(line.c_str(), "%lld,%d,%lf,%lf", &k, &robot, &render, &vision) == 4) timing_[{k, robot}] = {render, vision};
  }
}

std::optional<FrameData> RecordingSource::next() {
  std::optional<FrameData> f = reader_->next();
  if (!f) return f;
  for (auto& r : f->robots)
    if (const auto it = timing_.find({f->k, r.id}); it != timing_.end()) std::tie(r.render_ms, r.vision_ms) = it->second;
  if (header_.images) {
    for (auto& r : f->robots) {
      const fs::path p = fs::path(header_.dir) / image_name(r.id, f->k);
      if (const std::string why = why_not_readable_file(p.string()); !why.empty())
        throw ConfigError(p.string(), why, "an image for every frame (recording.json says \"images\": true)");
      r.obs.image = read_png(p.string());
    }
  }
  return f;
}

long long RecordingSource::fast_lines() const { return reader_->fast_lines(); }
long long RecordingSource::strict_lines() const { return reader_->strict_lines(); }

Json RecordingSource::client_camera(int robot) const {
  for (const auto& r : header_.robots)
    if (r.id == robot) return r.camera;
  return Json::object();
}

bool RecordingSource::detects_blobs() const {
  for (const auto& r : header_.robots)
    if (r.blobs) return true;
  return false;
}

}  // namespace omniloc::harness
