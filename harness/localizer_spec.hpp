#pragma once
// A localizer as the user gave it and where (harness/localizer_registry.hpp reads and builds it).
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/json_reader.hpp"

namespace omniloc::harness {

/// {"type": ..., params...} and its place in the user's input: taken once from where it enters (a
/// scenario's "localizer", a sweep's "localizers" entry, --localizer) and carried to the registry
/// whichever scenario it ends up in, so every error in it names the place it was written.
struct LocalizerSpec {
  LocalizerSpec() = default;
  LocalizerSpec(Json json, std::string path) : json(std::move(json)), path(std::move(path)) {}
  Json json = Json{{"type", "odometry_only"}};  ///< an object; an external localizer's paths made absolute
  std::string path = "/localizer";               ///< its JSON path there: "/localizer", "--localizer", "/localizers/2"
  /// Its "type" when that is a string, else "" (reading it strictly reports what is wrong).
  std::string type() const {
    const auto it = json.find("type");
    return it != json.end() && it->is_string() ? it->get<std::string>() : std::string();
  }
};

/// A ConfigError in a LocalizerSpec: its path is already where the user wrote the localizer, so a
/// caller that names a scenario's other errors by where that scenario came from leaves it as it is.
class LocalizerError : public ConfigError {
 public:
  explicit LocalizerError(const ConfigError& e) : ConfigError(e) {}
};

}  // namespace omniloc::harness
