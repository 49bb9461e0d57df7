#include "harness/recording/recording_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <ostream>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "core/version.hpp"
#include "external/external_localizer.hpp"
#include "external/sha256.hpp"
#include "harness/external_session.hpp"
#include "harness/frame_source.hpp"
#include "harness/recording/format/frame_codec.hpp"
#include "harness/recording/format/gzip.hpp"
#include "harness/recording/format/header.hpp"
#include "harness/recording/format/values.hpp"
#include "harness/render_frame.hpp"
#include "harness/run_directory.hpp"

namespace omniloc::harness {

namespace fs = std::filesystem;
using recording_values::pose_json;

RecordResult record_scenario(const Scenario& sc, const RecordOptions& opt) {
  RecordResult result;
  result.seed = opt.seed.value_or(sc.seed);
  RunDirectory dir(opt.out_dir.empty() ? "results/recordings/" + sc.name + "/" + std::to_string(result.seed) : opt.out_dir);
  LiveSource source(sc, result.seed, true);
  if (opt.images) {
    std::error_code ec;
    fs::create_directories(fs::path(dir.staging()) / "images", ec);
    if (ec) throw IoError("cannot create folder", (fs::path(dir.staging()) / "images").string(), ec.message());
  }
  std::string frames;
  std::string timing = "k,robot,render_ms,vision_ms\n";  // wall time: the one file that differs between recordings of a run
  while (auto f = source.next()) {
    frames += frame_to_json(*f).dump() + "\n";
    if (opt.on_frame) opt.on_frame(*f);
    for (const auto& r : f->robots) {
      char row[128];
      std::snprintf(row, sizeof row, "%lld,%d,%.4f,%.4f\n", f->k, r.id, r.render_ms, r.vision_ms);
      timing += row;
    }
    if (opt.images)
      for (const auto& r : f->robots)
        if (r.obs.image) {
          const std::string path = (fs::path(dir.staging()) / image_name(r.id, f->k)).string();
          write_png(*r.obs.image, path);
          std::error_code ec;
          const auto bytes = fs::file_size(path, ec);
          if (!ec) result.image_bytes += bytes;
        }
    ++result.frames;
    if (opt.log && f->k % static_cast<long long>(std::max(1.0, 10 * sc.camera_rate)) == 0 && f->k > 0) *opt.log << "  t = " << f->t << " s\n";
  }
  Json scenario = sc.input;
  scenario["name"] = sc.name;
  scenario["seed"] = result.seed;
  Json robots = Json::array();
  for (int id : sc.localized_robots())
    robots.push_back({{"id", id}, {"start", pose_json(sc.robot(id)->spec.start)}, {"camera", source.client_camera(id)}, {"blobs", source.detects_blobs()}});
  const Json header = {{"format", kRecordingFormat},
                       {"omniloc", build_info_json()},
                       {"name", sc.name},
                       {"seed", result.seed},
                       {"scenario", scenario},
                       {"scenario_source", sc.source},
                       {"field", sc.input.contains("field") ? sc.input["field"] : Json(sc.field.name)},
                       {"field_markings", field_for_client(sc.field)},
                       {"field_fingerprint", sc.field.fingerprint()},
                       {"camera_rate_hz", sc.camera_rate},
                       {"duration_s", sc.duration},
                       {"frames", result.frames},
                       {"frames_file", kFramesFile},
                       {"robots", robots},
                       {"ground_truth", true},
                       {"images", opt.images},
                       {"render", source.render_device()},
                       {"frames_sha256", external::sha256_hex(frames)}};
  const std::string gz = gzip_compress(frames);
  result.frames_bytes = gz.size();
  result.frames_text_bytes = frames.size();
  dir.write(kFramesFile, gz);
  dir.write("timing.csv", timing);
  dir.write("recording.json", header.dump(2) + "\n");
  dir.commit();
  result.out_dir = dir.final_dir();
  return result;
}

}  // namespace omniloc::harness
