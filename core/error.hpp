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

}  // namespace omniloc
