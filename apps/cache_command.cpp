#include "apps/cache_command.hpp"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "core/path_check.hpp"

namespace omniloc::app {

const cli::Command kCache{
    "cache", "list|size|prune", 1, 1,
    "The world cache: recordings of the worlds runs and sweeps drew, kept once per machine and replayed\n"
    "into every later run of the same world with any localizer (docs/recording.md \"World cache\").\n"
    "Folder: results/cache/worlds, or OMNILOC_CACHE (\"off\": none); size limit 20G, or OMNILOC_CACHE_MAX_SIZE.\n"
    "  list   each entry: key, scenario, seed, images, frames, size, last used (newest first)\n"
    "  size   the cache's folder, entries and bytes\n"
    "  prune  remove entries unused for longer than --older-than, then the least recently used ones\n"
    "         until the cache holds at most --max-size; entries in use by a run are kept",
    {{"--cache", "DIR", "the cache folder (default: OMNILOC_CACHE, else results/cache/worlds)"},
     {"--older-than", "DAYS", "prune: entries not used for more than DAYS days (a number >= 0)"},
     {"--max-size", "SIZE", "prune: keep at most SIZE bytes (e.g. 500M, 20G; 0 empties the cache)"}}};

harness::WorldCacheOptions cache_options(const cli::Args& a) {
  harness::WorldCacheOptions o = harness::world_cache_from_env();
  if (a.has("--cache")) {
    const std::string d = a.value("--cache");
    if (d.empty()) throw cli::UsageError("--cache needs a folder");
    require_writable(d, "--cache", true);
    o.dir = std::filesystem::absolute(d).lexically_normal().string();
  }
  if (a.has("--no-cache")) {
    if (a.has("--cache")) throw cli::UsageError("--cache and --no-cache contradict each other");
    o.dir.clear();
  }
  // A folder the user named in the environment is checked like --cache (the default is ours).
  const char* env = std::getenv("OMNILOC_CACHE");
  if (!a.has("--cache") && !o.dir.empty() && env && *env) require_writable(o.dir, "OMNILOC_CACHE", true);
  return o;
}

namespace {

std::string when(std::time_t t) {
  char b[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(b, sizeof b, "%Y-%m-%d %H:%M UTC", &tm);
  return b;
}

}  // namespace

int cmd_cache(const cli::Args& a) {
  const std::string what = a.positional[0];
  if (what != "list" && what != "size" && what != "prune") throw cli::UsageError("cache needs list, size or prune, got \"" + what + "\"");
  if (what != "prune" && (a.has("--older-than") || a.has("--max-size"))) throw cli::UsageError("--older-than and --max-size go with prune");
  harness::WorldCacheOptions o = cache_options(a);
  if (o.dir.empty()) {
    std::cout << "world cache: off (OMNILOC_CACHE=" << (std::getenv("OMNILOC_CACHE") ? std::getenv("OMNILOC_CACHE") : "") << ")\n";
    return 0;
  }
  harness::WorldCache cache(o);
  if (what == "list") {
    const auto entries = cache.list();
    std::printf("%-32s  %-28s %6s %6s %7s %11s  %s\n", "key", "scenario", "seed", "images", "frames", "size", "last used");
    std::uint64_t total = 0;
    for (const auto& e : entries) {
      total += e.bytes;
      if (!e.complete) {
        std::printf("%-32s  %-28s %6s %6s %7s %11s  %s\n", e.key.c_str(), "(incomplete: being drawn or interrupted)", "", "", "",
                    harness::format_bytes(e.bytes).c_str(), when(e.last_used).c_str());
        continue;
      }
      std::printf("%-32s  %-28s %6llu %6s %7lld %11s  %s\n", e.key.c_str(), e.scenario.c_str(), static_cast<unsigned long long>(e.seed),
                  e.images ? "yes" : "no", e.frames, harness::format_bytes(e.bytes).c_str(), when(e.last_used).c_str());
    }
    std::cout << entries.size() << " entries, " << harness::format_bytes(total) << " in " << o.dir << "\n";
    return 0;
  }
  if (what == "size") {
    const auto entries = cache.list();
    std::uint64_t total = 0;
    for (const auto& e : entries) total += e.bytes;
    std::cout << o.dir << ": " << entries.size() << " entries, " << harness::format_bytes(total) << " (" << total << " bytes); limit "
              << (o.max_bytes ? harness::format_bytes(o.max_bytes) : std::string("none")) << "\n";
    return 0;
  }
  std::optional<double> older;
  std::optional<std::uint64_t> max;
  if (a.has("--older-than")) older = a.number("--older-than", 0.0, 0.0, 1e6) * 86400.0;
  if (a.has("--max-size")) max = harness::parse_byte_size(a.value("--max-size"), "--max-size");
  if (!older && !max) throw cli::UsageError("prune needs --older-than DAYS and/or --max-size SIZE");
  const auto r = cache.prune(older, max);
  std::cout << "removed " << r.removed << " entries (" << harness::format_bytes(r.freed) << "), kept " << r.kept
            << (r.busy ? " (" + std::to_string(r.busy) + " in use)" : std::string()) << "; " << harness::format_bytes(r.left) << " left in "
            << o.dir << "\n";
  return 0;
}

}  // namespace omniloc::app
