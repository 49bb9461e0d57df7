// libFuzzer target over the readers of user input: the strict JSON reader, then the scenario, sweep
// and experiment-description parsers (chosen by the document's shape, as `omniloc validate` does).
// The only acceptable failure is a ConfigError; any other exception, a crash, a sanitizer report or
// a timeout is a finding. Every finding becomes a test in tests/robust_input_test.cpp.
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
#include "harness/scenario.hpp"
#include "harness/sweep.hpp"

namespace {

// Sweep files name scenario files relative to themselves: the input is written next to a copy of
// the quickstart scenario so that entries such as "quickstart.json" resolve.
const std::string& sweep_dir() {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / ("omniloc_fuzz_" + std::to_string(::getpid()))).string();
    std::filesystem::create_directories(d);
    std::filesystem::copy_file(std::string(OMNILOC_SOURCE_DIR) + "/scenarios/quickstart.json", d + "/quickstart.json",
                               std::filesystem::copy_options::overwrite_existing);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const omniloc::Json j = omniloc::parse_json_strict(text, "fuzz input");
    if (j.is_object() && j.contains("experiment")) {
      (void)omniloc::experiments::parse_cooperative_001(j);
    } else if (j.is_object() && j.contains("scenarios") && !j.contains("robots")) {
      const std::string file = sweep_dir() + "/sweep.json";
      std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
      (void)omniloc::harness::load_sweep(file);
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
