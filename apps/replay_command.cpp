// `omniloc replay`: a localizer on a recording's frames, the run folder `run` would write.
#include "apps/commands.hpp"

#include <filesystem>
#include <iostream>

#include "apps/command_support.hpp"
#include "harness/recording/recording_source.hpp"
#include "harness/recording/replay_scenario.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"

namespace omniloc::app {

const cli::Command kReplay{"replay", "RECORDING", 1, 1,
                           "Run a localizer on a recording's frames: the run folder `omniloc run` writes for the recorded\n"
                           "scenario and seed with that localizer, without simulating or rendering (docs/recording.md).",
                           {{"--localizer", "JSON|FILE", "the localizer, as a scenario's \"localizer\" object: inline JSON or a file holding it (required)"},
                            {"--seed", "N", "seed of the localizer's random stream (default: the recording's seed)"},
                            {"--debug-view", "", "also write view.jsonl: per frame, the line points and blobs the localizer was given and the\n"
                                              "covariance and particles it held, for `omniloc view` (docs/viewer.md)"},
                            {"-o", "DIR", "results folder; must not exist or be empty unless --overwrite"},
                            {"--overwrite", "", "replace what is at -o DIR"},
                            {"--quiet", "", "no progress log on stderr"}}};


int cmd_replay(const cli::Args& a) {
  const harness::LocalizerSpec localizer(localizer_values(a.value("--localizer"), "replay", false).front(), "--localizer");
  check_output_target(a, true);
  harness::RecordingHeader header = harness::RecordingHeader::read(a.positional[0]);
  const harness::Scenario s = harness::replay_scenario(header, localizer);
  harness::RecordingSource source(std::move(header));  // reads and checks every frame before any work
  harness::RunOptions o;
  o.seed = a.has("--seed") ? a.unsigned_integer("--seed", 0, kMaxSeed) : source.header().seed;
  o.out_dir = a.value("-o");
  o.replay = true;
  o.debug_view = a.has("--debug-view");
  if (!a.has("--quiet")) o.log = &std::cerr;
  Json provenance = Json::object();
  if (!source.header().render.is_null()) provenance["render"] = source.header().render;
  provenance["replay"] = {{"recording", std::filesystem::absolute(a.positional[0]).lexically_normal().string()},
                          {"format", source.header().format},
                          {"recorded_seed", source.header().seed},
                          {"recorded_with", harness::recorded_with(source.header())}};
  const auto r = harness::run_frames(s, *o.seed, source, o, provenance);
  std::cout << "replay of " << a.positional[0] << " (scenario " << s.name << ", seed " << r.seed << "), localizer "
            << r.summary["localizer"].get<std::string>() << "\n"
            << r.table << "results: " << r.out_dir << "\n";
  return 0;
}

}  // namespace omniloc::app
