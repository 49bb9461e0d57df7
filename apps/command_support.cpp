#include "apps/command_support.hpp"

#include <filesystem>
#include <iostream>

#include "core/error.hpp"
#include "core/install_paths.hpp"
#include "core/json_parse.hpp"
#include "core/path_check.hpp"
#include "external/external_config.hpp"

namespace omniloc::app {

void check_output_target(const cli::Args& a, bool folder) {
  const std::string out = a.value("-o");
  if (out.empty()) return;
  require_writable(out, "-o", folder, true);
  if (a.has("--overwrite")) return;
  std::error_code ec;
  const auto st = std::filesystem::symlink_status(out, ec);
  if (ec || !std::filesystem::exists(st)) return;
  if (std::filesystem::is_directory(st) && std::filesystem::is_empty(out, ec) && !ec) return;
  throw UsageError("-o " + out + " exists and is " + (std::filesystem::is_directory(st) ? "a folder with content" : "a file") +
                   "; give --overwrite to replace it, or another -o");
}

std::string shipped_or_given(const std::string& file) {
  namespace fs = std::filesystem;
  const fs::path p(file);
  std::error_code ec;
  if (p.empty() || p.is_absolute() || fs::exists(p, ec)) return file;
  const fs::path shipped = (share_dir() / p).lexically_normal();
  if (!fs::is_regular_file(shipped, ec)) return file;
  std::cerr << "omniloc: using " << shipped.string() << "\n";
  return shipped.string();
}

std::vector<Json> localizer_values(const std::string& v, const std::string& command, bool arrays) {
  const auto first = v.find_first_not_of(" \t\n");
  if (first == std::string::npos)
    throw UsageError(command + " needs --localizer JSON|FILE (e.g. --localizer '{\"type\": \"matching\"}')");
  const bool inline_json = v[first] == '{' || (arrays && v[first] == '[');
  Json j = inline_json ? parse_json_strict(v, "--localizer") : read_json_strict(v, "--localizer");
  std::vector<Json> out = arrays && j.is_array() ? std::vector<Json>(j.begin(), j.end()) : std::vector<Json>{j};
  for (Json& l : out) {
    if (!l.is_object())
      throw ConfigError("--localizer", json_brief(l), std::string("a localizer object {\"type\": ...}") + (arrays ? " (or an array of them)" : ""));
    external::anchor_external_paths(l);
  }
  return out;
}

}  // namespace omniloc::app
