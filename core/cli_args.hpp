#pragma once
// Strict command-line parsing: each command declares its options in a table (name, value or flag,
// help line), so `omniloc CMD --help` prints exactly what the command accepts and adding an option
// is adding a row. Every number is parsed whole and range-checked: "--seed -1", "--t 0.2abc",
// "--t nan" and "--frames-every 0" are usage errors naming the option (exit 2), never coerced.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace omniloc::cli {

/// Bad command line: exit 2, the message names the option and what it needs.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Option {
  std::string name;        ///< "--seed" or "-o"
  std::string value_name;  ///< "N", "DIR"...; empty for a flag
  std::string help;
};

struct Command {
  std::string name;        ///< "run"
  std::string arguments;   ///< "FILE" (for the usage line)
  std::size_t min_positional = 0, max_positional = 0;
  std::string summary;
  std::vector<Option> options;
};

class Args {
 public:
  std::vector<std::string> positional;
  bool help = false;  ///< --help or -h was given
  bool has(const std::string& name) const;
  /// The option's value (the last one when repeated), or `def`.
  std::string value(const std::string& name, const std::string& def = "") const;
  /// Whole-string integer in [lo, hi]; `def` when the option is absent.
  long long integer(const std::string& name, long long def, long long lo, long long hi) const;
  /// Whole-string non-negative integer (seeds); "-1" is an error, not 2^64 - 1.
  std::uint64_t unsigned_integer(const std::string& name, std::uint64_t def, std::uint64_t hi = UINT64_MAX) const;
  /// Whole-string finite number in [lo, hi].
  double number(const std::string& name, double def, double lo, double hi) const;

  std::vector<std::pair<std::string, std::string>> values;  ///< options with values, in order
  std::vector<std::string> flags;
};

/// Parses argv[first..argc) against `cmd`: unknown options, missing values, flags given a value and
/// a wrong number of positional arguments throw UsageError. "--name=value" is accepted too.
Args parse(const Command& cmd, int argc, char** argv, int first);

/// "usage: omniloc run FILE [options]" + summary + one line per option.
std::string help_text(const Command& cmd);

/// Whole-string parses, used by Args and for values inside options (such as --shard I/N).
bool parse_int(const std::string& s, long long& out);
bool parse_uint(const std::string& s, std::uint64_t& out);
bool parse_double(const std::string& s, double& out);

}  // namespace omniloc::cli
