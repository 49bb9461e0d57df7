#pragma once
// Seeded random streams. Every random draw in omniloc comes from an Rng passed in explicitly;
// streams are derived from the scenario seed and a stream name, so adding a stream never shifts
// the draws of another. Distributions are implemented here (not std::normal_distribution) so the
// numbers are identical across standard libraries.
#include <cstdint>
#include <random>
#include <string_view>

namespace omniloc {

/// SplitMix64 finaliser: a well-mixed 64-bit hash step.
std::uint64_t splitmix64(std::uint64_t x);

/// Seed of the stream `name` under master seed `seed` (FNV-1a of the name, mixed with the seed).
std::uint64_t derive_seed(std::uint64_t seed, std::string_view name);

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0) : engine_(seed) {}
  /// A child stream, independent of this one's state.
  static Rng stream(std::uint64_t seed, std::string_view name) { return Rng(derive_seed(seed, name)); }

  std::uint64_t next_u64() { return engine_(); }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n).
  std::uint64_t uniform_index(std::uint64_t n);
  /// Standard normal by Box-Muller (the spare value is cached).
  double normal();
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace omniloc
