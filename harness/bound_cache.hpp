#pragma once
// The bound cache (docs/results.md "The limit", "Cost."): the estimate-free part of a robot's accuracy
// bound (harness/scoring/bound.hpp BoundPart), kept once per set of frames. In a sweep many
// localizers replay one recorded world; the bound reads only what the frames gave them, so a replay
// whose bound is kept pays a digest of its frames and a file read instead of the bound's passes over
// every line point: every replay of a world drawn or recorded here (harness/bound_prepare.hpp
// computes its bounds then), else every one after the first.
//
// An entry is one file, <cache root>/bounds/<build fingerprint>/<key>.bound (harness/cache/cache_dirs.hpp):
// the key is the SHA-256 of everything bound_part reads (the frames' times, truth, camera_ok, line
// points, odometry and compass; the setup less `excluded`; the field's geometry); the folder is
// this build's fingerprint, which holds the bound's code, the compiler and the libraries. The file
// carries the SHA-256 of its own content and the number of frames: one that does not check (cut,
// changed, an older layout) is said on one line, removed and computed again: never used. Written to
// a temporary name and renamed, so a reader never sees half an entry. Hits refresh the file's
// time; a write prunes the least recently used entries past max_bytes, and removes a writer's
// temporary an hour old (left by a process that died mid-write). A cache that cannot be
// written never costs a run: one warning line per process (core/cache_root.hpp), the run goes on.
// OMNILOC_CACHE=off: nothing is read or written.
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "harness/frame_data.hpp"
#include "harness/run_record.hpp"
#include "harness/scenario.hpp"
#include "harness/scoring/bound.hpp"

namespace omniloc::harness {

struct BoundCacheOptions {
  std::string dir;                         ///< the entries' folder; empty: no cache
  std::string prune_root;                  ///< the folder pruned (every build's entries); empty: `dir`
  std::uint64_t max_bytes = 512ULL << 20;  ///< prune least recently used entries past this (all builds' folders)
  std::ostream* log = nullptr;             ///< damaged entries, one line each
};

/// build_cache_dir("bounds") (empty when caching is off), pruned over every build's folder under
/// bounds/ to 512 MiB, damaged entries said on stderr.
BoundCacheOptions bound_cache_from_env();

/// Lower-case hex SHA-256 of everything bound_part(robot, setup) reads.
std::string bound_key(const RobotRecord& robot, const BoundSetup& setup);

class BoundCache {
 public:
  explicit BoundCache(BoundCacheOptions o) : o_(std::move(o)) {}
  const BoundCacheOptions& options() const { return o_; }
  /// The entry's path ("" without a cache).
  std::string entry_path(const std::string& key) const;
  /// The part kept under `key` for `frames` frames when the entry is there and checks; a damaged one
  /// is said on the log and removed.
  std::optional<BoundPart> find(const std::string& key, std::size_t frames) const;
  /// Keeps `part` under `key`; a cache that cannot be written is reported once and left alone.
  void store(const std::string& key, const BoundPart& part) const;

 private:
  void prune() const;
  BoundCacheOptions o_;
};

/// bound_robot through `cache`: the part found under the frames' key, or computed and kept.
/// Byte for byte the result of bound_robot(robot, setup).
RobotBound bound_robot_cached(const RobotRecord& robot, const BoundSetup& setup, const BoundCache& cache);

/// What the bound of robot `id` takes from the scenario (the field, the camera's geometry, latency
/// and vibration, the declared odometry and compass noise, kidnaps and teleports): scoring's setup.
BoundSetup bound_setup(const Scenario& sc, int id, bool start_pose_given);

/// A frame as scoring records what the bound reads of it (harness/runner.cpp robot_frame: the same
/// fields, the same conversions), so that a recording's frames give scoring's key
/// (harness/bound_prepare.hpp).
FrameRecord bound_frame(const RobotFrame& rf);

/// The serialized entry of `part` (for tests: what store() writes) and its reading back (nullopt
/// with `why` set when it does not check).
std::string encode_bound_part(const BoundPart& part);
std::optional<BoundPart> decode_bound_part(const std::string& bytes, std::size_t frames, std::string* why = nullptr);

}  // namespace omniloc::harness
