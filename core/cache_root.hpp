#pragma once
// Where omniloc keeps what it computes once and reuses (docs/recording.md section 9): distance maps,
// mirror calibration maps, colour tables and recorded worlds, all under one root per user, as ccache,
// pip and Mesa's shader cache do, so that nothing lands in the working directory and a world drawn in
// one clone or folder is replayed in every other.
//
// Every entry's name or key carries what determines its content (field, camera, build fingerprint),
// so two clones, two commits' builds and two users' runs can share one root without a wrong hit.
// A root that cannot be created or written never costs a run: the run goes on uncached, and the
// first such failure in a process is said in one warning line on stderr.
#include <string>

namespace omniloc::cache {

/// The root folder of every cache, absolute and normalised, or "" when caching is off. Looked up at
/// every call (a test or the command line may change the environment):
///   1. $OMNILOC_CACHE when set: the root itself; "off", "0" or empty: no cache at all;
///   2. $XDG_CACHE_HOME/omniloc when XDG_CACHE_HOME is an absolute path (the XDG Base Directory
///      specification ignores a relative one);
///   3. $HOME/.cache/omniloc when HOME is an absolute path;
///   4. "" (no home is known: nothing is cached).
/// A relative $OMNILOC_CACHE is taken from the working directory at the call.
std::string root();

/// The folder of one kind of entry under the root: "worlds", "fieldmaps", "vision". Not created
/// here; "" when caching is off.
std::string dir(const char* kind);

/// Says once per process, on stderr, that the cache could not be written and the run goes on without
/// it (`why`: the operating system's words with the file), and marks it unwritable for the rest of
/// the process, so later writes are not tried again (what is there is still read). Thread-safe.
void report_unwritable(const std::string& why);

/// True once report_unwritable() was called in this process.
bool unwritable();

}  // namespace omniloc::cache
