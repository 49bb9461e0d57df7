#pragma once
// `omniloc cache` (the world cache, docs/recording.md "World cache") and the options run and sweep
// share to choose it.
#include "core/cli_args.hpp"
#include "harness/cache/world_cache.hpp"

namespace omniloc::app {

/// The cache a command uses: the environment's (OMNILOC_CACHE, OMNILOC_CACHE_MAX_SIZE), then its
/// --cache DIR / --no-cache options.
harness::WorldCacheOptions cache_options(const cli::Args& a);

}  // namespace omniloc::app
