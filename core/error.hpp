#pragma once
// The one error type for bad configuration (scenario, sweep, preset, calibration files).
// It names where (a JSON pointer such as /robots/0/start/x), what was found and what was expected.
#include <stdexcept>
#include <string>

namespace omniloc {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string path, std::string value, std::string expected);
  const std::string& path() const { return path_; }
  const std::string& value() const { return value_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string path_, value_, expected_;
};

/// A failure of the machinery (GL context, I/O) rather than of the user's input.
class RuntimeFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The operating system refused an operation on a file or folder. what() names the action, the path
/// and the cause in the system's words: "cannot write results/x.tmp: No space left on device".
/// Callers that can go on without the file (the caches) tell it apart by type and path.
class IoError : public RuntimeFailure {
 public:
  /// `err`: the errno value the system call left.
  IoError(const std::string& action, std::string path, int err);
  /// `why`: the cause in words, when it is not an errno value (std::error_code::message()).
  IoError(const std::string& action, std::string path, const std::string& why);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace omniloc
