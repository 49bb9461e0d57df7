#pragma once
// The world cache (docs/recording.md "World cache"): recordings of worlds kept once per machine, so
// a world (a scenario without its localizer, a seed) is drawn once, whichever sweep folder, `omniloc
// run`, shard or Slurm task needs it, and every later run with a localizer replays it.
//
// An entry is a recording folder under <cache root>/worlds/<key>/ (core/cache_root.hpp) with a manifest (entry.json: the size
// and SHA-256 of every file) and a `last_used` stamp. The key is the SHA-256 of everything that
// determines the frames: the scenario's effective configuration without the localizer, name,
// description and scoring; the seed; the noise profile; the field's geometry; the content of every
// file the scenario names; whether images were kept; the fingerprint of this build's simulation,
// rendering, vision and recording code and data (cmake/world_fingerprint.cmake), the compiler and
// the libraries; the OSMesa library drawing the pixels. A change to any of them misses the cache.
//
// Concurrency: one lock file per key. A run holds it shared while it replays the entry; drawing an
// entry, removing a damaged one and eviction hold it exclusively (eviction skips entries in use).
// A damaged entry (a file cut, changed, missing; no manifest) is reported on one line, removed and
// drawn again: never used. A cache that cannot be written (a full disk, a read-only folder, no
// permission) never costs a run: run_with_world_cache runs it live instead, with one warning.
#include <cstdint>
#include <ctime>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "harness/runner.hpp"
#include "harness/scenario.hpp"

namespace omniloc::harness {

struct WorldCacheOptions {
  std::string dir;                ///< the cache folder; empty: no cache
  std::uint64_t max_bytes = 0;    ///< evict least recently used entries past this size (0: no limit)
  std::ostream* log = nullptr;    ///< one line per hit, draw, damaged entry and eviction
};

/// The cache root's worlds/ folder (core/cache_root.hpp: OMNILOC_CACHE, else the XDG cache folder),
/// 20 GiB at most, or OMNILOC_CACHE_MAX_SIZE (bytes, or with K, M, G, T: "500M").
WorldCacheOptions world_cache_from_env();
/// "20G", "500M", "1048576": bytes. Throws ConfigError naming `what` otherwise.
std::uint64_t parse_byte_size(const std::string& text, const std::string& what);
/// "12.5 MiB".
std::string format_bytes(std::uint64_t bytes);

/// Why `sc`'s frames cannot come from the cache (empty when they can): a localizer without vision
/// (its live run sees no exposure-search pauses), PNG frames asked for, a renderer other than OSMesa
/// (a GPU's pixels depend on the machine, which the key does not hold).
std::string world_cache_ineligible(const Scenario& sc, const RunOptions& opt);

/// The key of (`sc` without its localizer, `seed`) with or without images; throws ConfigError when a
/// file the scenario names cannot be read.
std::string world_key(const Scenario& sc, std::uint64_t seed, bool images);

/// A world being replayed: the recording folder, held (shared lock) until destroyed.
class WorldLease {
 public:
  WorldLease(std::string dir, std::string key, bool drawn, int fd) : dir_(std::move(dir)), key_(std::move(key)), drawn_(drawn), fd_(fd) {}
  WorldLease(WorldLease&& o) noexcept : dir_(std::move(o.dir_)), key_(std::move(o.key_)), drawn_(o.drawn_), fd_(o.fd_) { o.fd_ = -1; }
  WorldLease(const WorldLease&) = delete;
  WorldLease& operator=(const WorldLease&) = delete;
  WorldLease& operator=(WorldLease&&) = delete;
  ~WorldLease();
  const std::string& dir() const { return dir_; }
  const std::string& key() const { return key_; }
  bool drawn() const { return drawn_; }  ///< drawn by this call (a miss), not found

 private:
  std::string dir_, key_;
  bool drawn_ = false;
  int fd_ = -1;
};

/// The world cache could not be written (a full disk, a read-only folder, no permission, a quota):
/// what() has the file and the system's words. The partial entry is removed before it is thrown.
class WorldCacheUnwritable : public IoError {
 public:
  explicit WorldCacheUnwritable(const IoError& e) : IoError(e) {}
};

struct WorldEntryInfo {
  std::string key;
  std::string scenario;
  std::uint64_t seed = 0;
  bool images = false;
  long long frames = 0;
  std::uint64_t bytes = 0;
  std::time_t last_used = 0;
  bool complete = true;  ///< false: no manifest (a draw was interrupted, or it is being drawn)
};

struct PruneResult {
  std::size_t removed = 0, kept = 0, busy = 0;
  std::uint64_t freed = 0, left = 0;
};

class WorldCache {
 public:
  explicit WorldCache(WorldCacheOptions o);
  const WorldCacheOptions& options() const { return o_; }
  /// The entry of `key` if it is there and whole (checked against its manifest), held shared.
  std::optional<WorldLease> find(const std::string& key);
  /// The entry of (`sc`, `seed`, `images`): found, or drawn now (record_scenario) while other
  /// processes wanting it wait; a damaged one is removed and drawn again. Throws WorldCacheUnwritable
  /// when the entry cannot be written, leaving no partial entry.
  WorldLease get(const Scenario& sc, std::uint64_t seed, bool images);
  std::vector<WorldEntryInfo> list() const;
  std::uint64_t size() const;
  /// Removes entries unused for more than `older_than_s` seconds, then the least recently used ones
  /// until the cache holds at most `max_bytes`; entries in use are kept.
  PruneResult prune(std::optional<double> older_than_s, std::optional<std::uint64_t> max_bytes);
  enum class Removal { kRemoved, kBusy, kFailed };
  /// Removes the entry of `key` unless a run replays it or draws it now (kBusy).
  Removal remove(const std::string& key);

 private:
  std::string entry_dir(const std::string& key) const;
  int lock(const std::string& key) const;       ///< the key's lock file, open; WorldCacheUnwritable when it cannot be
  int open_lock(const std::string& key) const;  ///< lock()'s work, throwing IoError
  std::string damage(const std::string& key) const;  ///< why the entry is not whole ("" when it is)
  WorldCacheOptions o_;
};

/// `omniloc run` through the cache: the run's world is replayed from its entry (drawn first on a
/// miss) when world_cache_ineligible() is empty, else run live. The run folder is byte-identical to
/// the live run's but for summary.json's provenance block ("world_cache": the key) and timing.csv's
/// wall-clock times. External clients are started first: the entry is drawn with images when the
/// client's `ready` asks for them. When the cache cannot be written the run goes on live (uncached),
/// after one warning line on stderr naming the cause.
RunResult run_with_world_cache(const Scenario& sc, const RunOptions& opt, WorldCache& cache);

}  // namespace omniloc::harness
