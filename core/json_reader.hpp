#pragma once
// Strict reading of JSON objects: every value is checked for type and range, every error names
// its JSON pointer, and finish() rejects keys nobody read, so a misspelt key never passes silently.
#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace omniloc {

using Json = nlohmann::json;

/// Short rendering of a JSON value for error messages.
std::string json_brief(const Json& v);
/// Appends a key or index to a JSON pointer.
std::string json_child(const std::string& path, const std::string& key);
std::string json_child(const std::string& path, std::size_t index);

class JsonReader {
 public:
  /// Throws ConfigError unless `j` is an object. When `effective` is given, every value read
  /// (defaults included) is recorded there, so a run can save its effective configuration.
  JsonReader(const Json& j, std::string path, Json* effective = nullptr);

  const std::string& path() const { return path_; }
  std::string child_path(const std::string& key) const { return json_child(path_, key); }
  bool has(const std::string& key) const;
  /// Marks a key as known without reading it (e.g. "comment").
  void allow(const std::string& key);

  double number(const std::string& key, std::optional<double> def,
                double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity());
  /// Like number() but the interval is open at lo (value must be > lo).
  double positive(const std::string& key, std::optional<double> def,
                  double hi = std::numeric_limits<double>::infinity());
  long long integer(const std::string& key, std::optional<long long> def,
                    long long lo = std::numeric_limits<long long>::min(),
                    long long hi = std::numeric_limits<long long>::max());
  bool boolean(const std::string& key, std::optional<bool> def);
  std::string string(const std::string& key, std::optional<std::string> def,
                     const std::vector<std::string>& allowed = {});
  /// Array of strings (any length), each one of `allowed` when that is not empty.
  std::vector<std::string> strings(const std::string& key, std::optional<std::vector<std::string>> def,
                                   const std::vector<std::string>& allowed = {});
  /// Fixed-length array of numbers.
  std::vector<double> numbers(const std::string& key, std::optional<std::vector<double>> def,
                              std::size_t length);
  /// A child object; nullopt when absent and optional.
  std::optional<JsonReader> object(const std::string& key, bool required = false);
  /// Raw access (the key counts as read); throws when required and absent.
  const Json* raw(const std::string& key, bool required = false);

  /// Throws on the first key that was never read or allowed.
  void finish() const;

 private:
  const Json* fetch(const std::string& key, bool required);
  template <class T>
  void record(const std::string& key, const T& v) {
    if (effective_) (*effective_)[key] = v;
  }
  const Json& j_;
  Json* effective_ = nullptr;
  std::string path_;
  std::set<std::string> seen_;
};

}  // namespace omniloc
