// libFuzzer target over the readers of user input: the strict JSON reader, then the scenario, sweep
// and experiment-description parsers (chosen by the document's shape, as `omniloc validate` does).
// The only acceptable failure is a ConfigError; any other exception, a crash, a sanitizer report or
// a timeout is a finding. Inputs that start with "olp\n" are instead a byte stream from an external
// localizer's client (docs/protocol.md): the olp/1 framing reader and the strict readers of ready and
// estimate, where the only acceptable failure is a ProtocolError. Inputs that start with "rec\n" are a
// recording (docs/recording.md): recording.json's text, a blank line, frames.jsonl's text, read by
// the recording reader as `omniloc replay` reads it and, when it reads, replayed through a built-in
// localizer (only a ConfigError is acceptable). Every finding
// becomes a test in tests/robust_input_test.cpp.
// Built by scripts/fuzz.sh (clang-14, -fsanitize=fuzzer,address,undefined); seed corpus: scenarios/.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/json_parse.hpp"
#include "experiments/cooperative_001.hpp"
#include "external/external_localizer.hpp"
#include "external/olp_framing.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "batch/sweep.hpp"
#include "core/install_paths.hpp"

namespace {

// Sweep files name scenario files relative to themselves: the input is written next to a copy of
// the quickstart scenario so that entries such as "quickstart.json" resolve.
const std::string& sweep_dir() {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / ("omniloc_fuzz_" + std::to_string(::getpid()))).string();
    std::filesystem::create_directories(d);
    std::filesystem::copy_file(std::string(omniloc::source_dir().string()) + "/scenarios/quickstart.json", d + "/quickstart.json",
                               std::filesystem::copy_options::overwrite_existing);
    return d;
  }();
  return dir;
}

}  // namespace

// A client's stdout as omniloc reads it: in pieces whose sizes come from the input itself (so the
// fuzzer explores split lines and split binary parts), every whole message through the strict readers.
void fuzz_olp_stream(std::string_view bytes) {
  using namespace omniloc::external;
  MessageReader reader;
  std::size_t pos = 0, round = 0;
  try {
    while (pos < bytes.size()) {
      const std::size_t piece = 1 + static_cast<unsigned char>(bytes[(round++ * 7) % bytes.size()]) * 3;
      reader.feed(bytes.substr(pos, piece));
      pos += std::min(piece, bytes.size() - pos);
      while (auto m = reader.next()) {
        if (m->type() == "ready") (void)ExternalLocalizer::parse_ready(m->header, {"mcl", "matching"});
        else if (m->type() == "estimate") {
          const auto k = m->header.find("k");
          (void)ExternalLocalizer::parse_estimate(m->header, k != m->header.end() && k->is_number_integer() ? k->get<long long>() : 0);
        }
      }
    }
  } catch (const ProtocolError&) {
    // The expected outcome for a faulty client: the run fails with this message.
  }
}

// A recording that reads is replayed through one built-in localizer, chosen by the input's length,
// into a scratch run folder: its values (not only its structure) reach the localizers, as with
// `omniloc replay` (a line point at -1e308 m once crashed matching and grid_global).
void replay_recording(const std::string& dir, std::size_t choice) {
  static const char* const kLocalizers[] = {"matching", "grid_global", "mcl", "hybrid", "landmarks", "odometry_only", "ukf_mh"};
  using namespace omniloc;
  harness::RecordingHeader header = harness::RecordingHeader::read(dir);
  const Json localizer = {{"type", kLocalizers[choice % std::size(kLocalizers)]}};
  const harness::Scenario sc = harness::replay_scenario(header, harness::LocalizerSpec(localizer, "--localizer"));
  harness::RecordingSource source(std::move(header));
  harness::RunOptions o;
  o.out_dir = sweep_dir() + "/replay";
  o.replay = true;
  std::filesystem::remove_all(o.out_dir);
  (void)harness::run_frames(sc, source.header().seed, source, o, Json::object());
}

// A recording folder written from the input, then read and every frame taken, as a replay does.
void fuzz_recording(std::string_view bytes) {
  const std::size_t sep = bytes.find("\n\n");
  const std::string dir = sweep_dir() + "/recording";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/recording.json", std::ios::binary | std::ios::trunc) << bytes.substr(0, sep);
  std::ofstream(dir + "/frames.jsonl", std::ios::binary | std::ios::trunc) << (sep == std::string_view::npos ? std::string_view() : bytes.substr(sep + 2));
  try {
    {
      omniloc::harness::RecordingSource source(omniloc::harness::RecordingHeader::read(dir));
      while (source.next()) {
      }
    }
    replay_recording(dir, bytes.size());
  } catch (const omniloc::ConfigError&) {
    // The expected outcome for a bad recording: exit 2 naming the file.
  }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (text.rfind("rec\n", 0) == 0) {
    try {
      fuzz_recording(std::string_view(text).substr(4));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "finding: recording: exception other than ConfigError: %s\n", e.what());
      std::abort();
    }
    return 0;
  }
  if (text.rfind("olp\n", 0) == 0) {
    try {
      fuzz_olp_stream(std::string_view(text).substr(4));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "finding: olp stream: exception other than ProtocolError: %s\n", e.what());
      std::abort();
    }
    return 0;
  }
  try {
    const omniloc::Json j = omniloc::parse_json_strict(text, "fuzz input");
    if (j.is_object() && j.contains("experiment")) {
      (void)omniloc::experiments::parse_cooperative_001(j);
    } else if (j.is_object() && j.contains("scenarios") && !j.contains("robots")) {
      const std::string file = sweep_dir() + "/sweep.json";
      std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
      (void)omniloc::batch::load_sweep(file);
    } else {
      (void)omniloc::harness::parse_scenario(j, "fuzz", "fuzz input");
    }
  } catch (const omniloc::ConfigError&) {
    // The expected outcome for bad input: exit 2 with a path.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "finding: exception other than ConfigError: %s\n", e.what());
    std::abort();
  }
  return 0;
}
