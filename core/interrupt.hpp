#pragma once
// What omniloc undoes when it is interrupted (SIGINT, SIGTERM, SIGHUP): it ends the process groups
// of the external clients it started and removes the staging folders of the runs it had not
// finished, says so in one line on stderr, then dies of the same signal (so a shell reports 130,
// 143 or 129, as for any interrupted program). kill -9 cannot be caught: the staging folder then
// stays until the next run into the same parent folder clears it (harness::remove_stale_partials).
//
// The handler may only use async-signal-safe calls, so everything it needs is kept in fixed tables
// of atomics and preallocated path buffers: registering is cheap and thread-safe.
namespace omniloc::interrupt {

/// Installs the handlers once (a signal that is ignored, e.g. under nohup, stays ignored).
void install();

/// A process group (its leader's pid) to end with TERM, then KILL after up to 2 s.
void watch_group(int pid);
void unwatch_group(int pid);

/// A folder to remove recursively on interruption (a run's staging folder); returns a slot for
/// unwatch_folder, or -1 when the table (256 entries) is full or the path is too long.
int watch_folder(const char* path);
void unwatch_folder(int slot);

/// Removes `path` and everything below it with async-signal-safe calls only (openat, getdents64,
/// unlinkat); what the handler uses, exposed for the tests. Returns false when something stayed.
bool remove_tree(const char* path);

}  // namespace omniloc::interrupt
