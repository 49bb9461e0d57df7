#pragma once
// Strict parsing of user-supplied JSON (scenario, sweep, experiment and field files).
// nlohmann's DOM parser recurses once per nesting level, and everything that later walks the value
// (dump, copy, destruction) recurses too: 65k levels of "[" overflow the stack. This parser builds
// the DOM through the SAX interface with an explicit stack and refuses, each as a ConfigError
// naming the JSON pointer where the parser stood:
//   - nesting deeper than kJsonMaxDepth (so every later recursive walk is bounded),
//   - texts larger than kJsonMaxBytes (read fully into memory),
//   - NUL bytes (C string handling elsewhere would silently cut the text or the message there),
//   - duplicate keys in one object (nlohmann keeps the last one silently),
//   - numbers that do not fit a double (1e400), and any syntax error.
#include <cstddef>
#include <string>
#include <string_view>

#include "core/json_reader.hpp"
#include "core/path_check.hpp"  // require_readable_file: data files named in a scenario

namespace omniloc {

/// Deepest nesting of arrays/objects accepted; the shipped files use at most 6.
inline constexpr std::size_t kJsonMaxDepth = 64;
/// Largest JSON text accepted (bytes); the largest shipped file is below 100 KiB.
inline constexpr std::size_t kJsonMaxBytes = 16u << 20;

/// Parses `text`; `source` names it in messages (a file name). Throws ConfigError.
Json parse_json_strict(std::string_view text, const std::string& source);

/// Reads and parses a JSON file. `where` is the JSON pointer or option that named the file (used in
/// the message when it cannot be read: missing, a directory, too large). Throws ConfigError.
Json read_json_strict(const std::string& path, const std::string& where);

}  // namespace omniloc
