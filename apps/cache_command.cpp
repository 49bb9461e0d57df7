#include "apps/cache_command.hpp"
#include "apps/commands.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>

#include "core/cache_root.hpp"
#include "core/error.hpp"
#include "core/path_check.hpp"
#include "core/path_check.hpp"

namespace omniloc::app {

namespace fs = std::filesystem;

const cli::Command kCache{
    "cache", "list|size|prune", 1, 1,
    "Every cache omniloc keeps, under one root: recorded worlds (worlds/: each world a run or sweep drew,\n"
    "replayed into every later run of it with any localizer), distance maps (fieldmaps/), mirror\n"
    "calibration maps and colour tables (vision/), accuracy bounds of replayed frames (bounds/).\n"
    "Docs: docs/recording.md \"World cache\".\n"
    "Root: OMNILOC_CACHE (\"off\": none), else $XDG_CACHE_HOME/omniloc, else ~/.cache/omniloc.\n"
    "Size limit of worlds/ while runs fill it: 20G, or OMNILOC_CACHE_MAX_SIZE.\n"
    "  list   each entry: kind, key or file, what it is, size, last used (newest first)\n"
    "  size   the root, and entries and bytes of each kind\n"
    "  prune  remove entries unused for longer than --older-than, then the least recently used ones\n"
    "         until the cache holds at most --max-size; worlds in use by a run are kept",
    {{"--cache", "DIR", "the cache root (default: OMNILOC_CACHE, else $XDG_CACHE_HOME/omniloc or ~/.cache/omniloc)"},
     {"--older-than", "DAYS", "prune: entries not used for more than DAYS days (a number >= 0)"},
     {"--max-size", "SIZE", "prune: keep at most SIZE bytes in all (e.g. 500M, 20G; 0 empties the cache)"}}};

harness::WorldCacheOptions cache_options(const cli::Args& a) {
  if (a.has("--cache") && a.has("--no-cache")) throw cli::UsageError("--cache and --no-cache contradict each other");
  // Through the environment, so that every cache of this process (and of the runs it starts) uses it.
  if (a.has("--cache")) {
    const std::string d = a.value("--cache");
    if (d.empty()) throw cli::UsageError("--cache needs a folder");
    // A folder named on the command line is checked like every output path (exit 2 with the
    // reason); the environment's and the default root are not: a root that cannot be written only
    // costs the caching (one warning, core/cache_root.hpp).
    require_writable(d, "--cache", true);
    std::error_code ec;
    const fs::path p = fs::absolute(d, ec);
    ::setenv("OMNILOC_CACHE", (ec ? fs::path(d) : p).lexically_normal().c_str(), 1);
  }
  if (a.has("--no-cache")) ::setenv("OMNILOC_CACHE", "off", 1);
  return harness::world_cache_from_env();
}

namespace {

std::string when(std::time_t t) {
  char b[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(b, sizeof b, "%Y-%m-%d %H:%M UTC", &tm);
  return b;
}

// One entry of any kind: a world (a folder under worlds/) or a file (a distance map, a calibration
// map, a colour table).
struct Entry {
  std::string kind;  ///< "world", "fieldmap", "calibration", "colour", "bound"
  std::string name;  ///< the world's key, or the file's name
  std::string what;  ///< scenario and seed of a world; empty for files (the name says it)
  std::uint64_t bytes = 0;
  std::time_t last_used = 0;
};

// The folder of a kind of file entry.
const char* folder_of(const std::string& kind) { return kind == "fieldmap" ? "fieldmaps" : kind == "bound" ? "bounds" : "vision"; }

// The files of the root's fieldmaps/<build>/, vision/<build>/ and bounds/<build>/ folders
// (harness/cache/cache_dirs.hpp, harness/bound_cache.hpp), named "<build>/<file>". A file being
// written (name.tmp.<pid>...) is not an entry yet.
std::vector<Entry> file_entries(const std::string& root) {
  std::vector<Entry> out;
  for (const char* kind : {"fieldmaps", "vision", "bounds"}) {
    std::error_code ec;
    for (fs::directory_iterator b(fs::path(root) / kind, ec), end; !ec && b != end; b.increment(ec)) {
      std::error_code e1;
      if (!b->is_directory(e1)) continue;
      for (fs::directory_iterator it(b->path(), e1); !e1 && it != end; it.increment(e1)) {
        const std::string n = it->path().filename().string();
        std::error_code e2;
        if (!it->is_regular_file(e2) || n.find(".tmp.") != std::string::npos) continue;
        struct stat st {};
        if (::stat(it->path().c_str(), &st) != 0) continue;
        Entry e;
        e.kind = std::string(kind) == "fieldmaps" ? "fieldmap"
                 : std::string(kind) == "bounds"  ? "bound"
                 : n.rfind("colour", 0) == 0      ? "colour"
                                                  : "calibration";
        e.name = b->path().filename().string() + "/" + n;
        e.bytes = static_cast<std::uint64_t>(st.st_size);
        e.last_used = std::max(st.st_mtime, st.st_atime);
        out.push_back(std::move(e));
      }
    }
  }
  return out;
}

std::vector<Entry> all_entries(const harness::WorldCache& worlds, const std::string& root) {
  std::vector<Entry> out;
  for (const auto& w : worlds.list()) {
    Entry e{"world", w.key, "", w.bytes, w.last_used};
    if (!w.complete) e.what = "(incomplete: being drawn or interrupted)";
    else {
      char s[512];
      std::snprintf(s, sizeof s, "%s, seed %llu, %lld frames%s", w.scenario.c_str(), static_cast<unsigned long long>(w.seed), w.frames,
                    w.images ? ", images" : "");
      e.what = s;
    }
    out.push_back(std::move(e));
  }
  for (auto& e : file_entries(root)) out.push_back(std::move(e));
  std::sort(out.begin(), out.end(), [](const Entry& a, const Entry& b) { return a.last_used != b.last_used ? a.last_used > b.last_used : a.name < b.name; });
  return out;
}

}  // namespace

int cmd_cache(const cli::Args& a) {
  const std::string what = a.positional[0];
  if (what != "list" && what != "size" && what != "prune") throw cli::UsageError("cache needs list, size or prune, got \"" + what + "\"");
  if (what != "prune" && (a.has("--older-than") || a.has("--max-size"))) throw cli::UsageError("--older-than and --max-size go with prune");
  harness::WorldCacheOptions o = cache_options(a);
  const std::string root = cache::root();
  if (root.empty()) {
    const char* env = std::getenv("OMNILOC_CACHE");
    std::cout << "cache: off (" << (env ? "OMNILOC_CACHE=" + std::string(env) : std::string("no OMNILOC_CACHE, XDG_CACHE_HOME or HOME")) << ")\n";
    return 0;
  }
  harness::WorldCache worlds(o);
  if (what == "list") {
    const auto entries = all_entries(worlds, root);
    std::printf("%-11s  %-56s %11s  %-20s  %s\n", "kind", "key or file", "size", "last used", "what");
    std::uint64_t total = 0;
    for (const auto& e : entries) {
      total += e.bytes;
      std::printf("%-11s  %-56s %11s  %-20s  %s\n", e.kind.c_str(), e.name.c_str(), harness::format_bytes(e.bytes).c_str(), when(e.last_used).c_str(),
                  e.what.c_str());
    }
    std::cout << entries.size() << " entries, " << harness::format_bytes(total) << " in " << root << "\n";
    return 0;
  }
  if (what == "size") {
    const auto entries = all_entries(worlds, root);
    std::uint64_t total = 0;
    std::cout << root << ":\n";
    for (const char* kind : {"world", "fieldmap", "calibration", "colour", "bound"}) {
      std::size_t n = 0;
      std::uint64_t bytes = 0;
      for (const auto& e : entries)
        if (e.kind == kind) ++n, bytes += e.bytes;
      total += bytes;
      std::printf("  %-11s %6zu entries %11s\n", kind, n, harness::format_bytes(bytes).c_str());
    }
    std::cout << "  in all: " << entries.size() << " entries, " << harness::format_bytes(total) << " (" << total << " bytes); worlds' limit "
              << (o.max_bytes ? harness::format_bytes(o.max_bytes) : std::string("none")) << "\n";
    return 0;
  }
  std::optional<double> older;
  std::optional<std::uint64_t> max;
  if (a.has("--older-than")) older = a.number("--older-than", 0.0, 0.0, 1e6) * 86400.0;
  if (a.has("--max-size")) max = harness::parse_byte_size(a.value("--max-size"), "--max-size");
  if (!older && !max) throw cli::UsageError("prune needs --older-than DAYS and/or --max-size SIZE");
  // Oldest use first, every kind together: what was used last is kept longest.
  std::vector<Entry> entries = all_entries(worlds, root);
  std::reverse(entries.begin(), entries.end());
  std::uint64_t total = 0, freed = 0;
  for (const auto& e : entries) total += e.bytes;
  std::size_t removed = 0, kept = 0, busy = 0;
  const std::time_t now = std::time(nullptr);
  for (const auto& e : entries) {
    const bool old = older && static_cast<double>(now - e.last_used) > *older;
    const bool over = max && total > *max;
    bool gone = false;
    if (old || over) {
      if (e.kind == "world") {
        const auto r = worlds.remove(e.name);
        gone = r == harness::WorldCache::Removal::kRemoved;
        if (r == harness::WorldCache::Removal::kBusy) ++busy;
      } else {
        std::error_code ec;
        const fs::path file = fs::path(root) / folder_of(e.kind) / e.name;
        gone = fs::remove(file, ec) && !ec;
        if (gone && fs::is_empty(file.parent_path(), ec)) fs::remove(file.parent_path(), ec);  // the build's folder, once empty
      }
    }
    if (!gone) {
      ++kept;
      continue;
    }
    ++removed;
    freed += e.bytes;
    total -= e.bytes;
  }
  std::cout << "removed " << removed << " entries (" << harness::format_bytes(freed) << "), kept " << kept
            << (busy ? " (" + std::to_string(busy) + " in use)" : std::string()) << "; " << harness::format_bytes(total) << " left in " << root
            << "\n";
  return 0;
}

}  // namespace omniloc::app
