#pragma once
// The client program of an external localizer as a child process (docs/protocol.md, section 7):
// started in its own process group with stdin and stdout as non-blocking pipes and stderr in a log
// file, told to die with omniloc (PR_SET_PDEATHSIG), ended as a group (SIGTERM, then SIGKILL) when
// it fails, when the run ends, and when omniloc itself is interrupted (SIGINT, SIGTERM, SIGHUP).
// Every wait has a deadline: nothing here can block for ever on a stalled client.
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "external/olp_framing.hpp"

namespace omniloc::external {

using Clock = std::chrono::steady_clock;

struct ProcessSpec {
  std::string program;                     ///< absolute path of the executable (resolve_program)
  std::vector<std::string> argv;           ///< argv[0] as the user wrote it, then the arguments
  std::string cwd;                         ///< absolute working directory
  std::map<std::string, std::string> env;  ///< added to (or replacing in) omniloc's environment
  std::string stderr_path;                 ///< the client's stderr goes here (created, truncated)
};

/// `name` as execvp would find it: a name with a '/' is taken against `cwd`, one without is looked
/// up on PATH. nullopt when no executable regular file is found.
std::optional<std::string> resolve_program(const std::string& name, const std::string& cwd);

/// "exited with status 3", "killed by signal 9 (Killed)".
std::string describe_wait_status(int status);

class ClientProcess {
 public:
  /// Starts the program; throws RuntimeFailure ("cannot start ...: <errno text>") when the exec fails.
  explicit ClientProcess(const ProcessSpec& spec);
  ~ClientProcess();  ///< terminate()
  ClientProcess(const ClientProcess&) = delete;
  ClientProcess& operator=(const ClientProcess&) = delete;

  enum class Io { kOk, kTimeout, kClosed };
  /// Writes all of `bytes` to the client's stdin before `deadline`. While the pipe is full it keeps
  /// reading the client's stdout into `reader`, so a client that writes while we write cannot
  /// deadlock us. kClosed: the client closed its stdin (exited).
  Io write_all(std::string_view bytes, Clock::time_point deadline, MessageReader& reader);
  /// The next whole message before `deadline`: kOk with `out` set, kTimeout, or kClosed when the
  /// client closed its stdout with no whole message left. Throws ProtocolError from the reader.
  Io read_message(Clock::time_point deadline, MessageReader& reader, std::optional<Message>& out);
  void close_stdin();
  /// Waits for the process to exit before `deadline`; its wait status, or nullopt on time-out.
  std::optional<int> wait_exit(Clock::time_point deadline);
  /// The exit status if the process has already exited (reaps it), else nullopt.
  std::optional<int> poll_exit();
  /// Ends the whole process group: SIGTERM, up to `grace` for it to go, then SIGKILL; reaps.
  void terminate(std::chrono::milliseconds grace = std::chrono::milliseconds(2000));
  /// The last `lines` lines of the client's stderr log ("" when empty or unreadable).
  std::string stderr_tail(int lines = 20) const;
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  int in_fd_ = -1, out_fd_ = -1;  // our ends: the client's stdin (we write), its stdout (we read)
  std::optional<int> status_;     // once reaped
  std::string stderr_path_;
  bool stdout_eof_ = false;
};

}  // namespace omniloc::external
