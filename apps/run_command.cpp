// `omniloc run`: one scenario, its world from the world cache unless --draw-each.
#include "apps/commands.hpp"

#include <iostream>

#include "apps/cache_command.hpp"
#include "apps/command_support.hpp"
#include "core/path_check.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"
#include "harness/cache/world_cache.hpp"

namespace omniloc::app {

const cli::Command kRun{"run", "FILE", 1, 1, "Run a scenario; results in results/runs/<scenario>/<seed>/ (or -o DIR).",
                        {{"--seed", "N", "seed (integer >= 0; default: the scenario's)"},
                         {"-o", "DIR", "results folder; must not exist or be empty unless --overwrite"},
                         {"--overwrite", "", "replace what is at -o DIR (a previous result, or anything else)"},
                         {"--frames", "DIR", "write the camera frames as PNG into DIR"},
                         {"--frames-every", "N", "with --frames: every N-th frame (integer in [1, 1000000])"},
                         {"--debug-view", "", "also write view.jsonl: per frame, the line points and blobs the localizer was given and the\n"
                                             "covariance and particles it held, for `omniloc view` (docs/viewer.md)"},
                         {"--draw-each", "", "simulate and render this run itself instead of replaying its world from the world cache\n"
                                             "(the results are the same byte for byte: docs/recording.md \"World cache\")"},
                         {"--cache", "DIR", "the cache root (default: OMNILOC_CACHE, else $XDG_CACHE_HOME/omniloc or ~/.cache/omniloc)"},
                         {"--no-cache", "", "neither read nor fill any cache (as OMNILOC_CACHE=off)"},
                         {"--quiet", "", "no progress log on stderr"}}};

int cmd_run(const cli::Args& a) {
  const auto s = harness::load_scenario(a.positional[0]);
  harness::RunOptions o;
  if (a.has("--seed")) o.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
  o.out_dir = a.value("-o");
  check_output_target(a, true);
  o.frames_dir = a.value("--frames");
  if (!o.frames_dir.empty()) require_writable(o.frames_dir, "--frames", true);
  o.frames_every = static_cast<int>(a.integer("--frames-every", o.frames_every, 1, 1000000));
  o.debug_view = a.has("--debug-view");
  if (!a.has("--quiet")) o.log = &std::cerr;
  if (a.has("--draw-each") && (a.has("--cache") || a.has("--no-cache"))) throw UsageError("--draw-each uses no cache: leave out --cache / --no-cache");
  harness::WorldCacheOptions co = app::cache_options(a);
  co.log = o.log;
  harness::WorldCache cache(co);
  const auto r = a.has("--draw-each") ? harness::run_scenario(s, o) : harness::run_with_world_cache(s, o, cache);
  std::cout << "scenario " << s.name << ", seed " << r.seed << ", localizer " << r.summary["localizer"].get<std::string>()
            << ", noise " << s.noise.name << "\n"
            << r.table << "results: " << r.out_dir << "\n";
  return 0;
}

}  // namespace omniloc::app
