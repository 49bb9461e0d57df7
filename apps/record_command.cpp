// `omniloc record`: a recording of everything a localizer is given (docs/recording.md).
#include "apps/commands.hpp"

#include <algorithm>
#include <iostream>

#include "apps/command_support.hpp"
#include "harness/bound_prepare.hpp"
#include "harness/recording/recording_writer.hpp"
#include "harness/scenario.hpp"

namespace omniloc::app {

const cli::Command kRecord{"record", "FILE", 1, 1,
                           "Simulate and perceive a scenario once, without a localizer, and write a recording of everything\n"
                           "a localizer is given (docs/recording.md); results/recordings/<scenario>/<seed>/ (or -o DIR).",
                           {{"--seed", "N", "seed (integer >= 0; default: the scenario's)"},
                            {"--images", "", "also keep every frame's image (lossless PNG, for clients that read pixels)"},
                            {"-o", "DIR", "recording folder; must not exist or be empty unless --overwrite"},
                            {"--overwrite", "", "replace what is at -o DIR"},
                            {"--quiet", "", "no progress log on stderr"}}};

int cmd_record(const cli::Args& a) {
  const auto s = harness::load_scenario(a.positional[0]);
  harness::RecordOptions o;
  if (a.has("--seed")) o.seed = a.unsigned_integer("--seed", 0, kMaxSeed);
  o.out_dir = a.value("-o");
  check_output_target(a, true);
  o.images = a.has("--images");
  if (!a.has("--quiet")) o.log = &std::cerr;
  harness::BoundPreparer bounds(s);  // its replays' bounds, kept in the cache (docs/results.md "Cost.")
  o.on_frame = [&bounds](const harness::FrameData& f) { bounds.add(f); };
  const auto r = harness::record_scenario(s, o);
  bounds.finish();
  const double minutes = std::max(1e-9, s.duration / 60.0);
  std::cout << "scenario " << s.name << ", seed " << r.seed << ": " << r.frames << " frames, frames.jsonl.gz " << r.frames_bytes / 1024
            << " KiB (" << static_cast<long long>(static_cast<double>(r.frames_bytes) / minutes / 1024) << " KiB per minute; "
            << r.frames_text_bytes / 1024 << " KiB of JSON lines)";
  if (o.images)
    std::cout << ", images " << r.image_bytes / (1024 * 1024) << " MiB ("
              << static_cast<long long>(static_cast<double>(r.image_bytes) / minutes / (1024 * 1024)) << " MiB per minute)";
  std::cout << "\nrecording: " << r.out_dir << "\n";
  return 0;
}

}  // namespace omniloc::app
