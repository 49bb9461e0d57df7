#include "external/external_config.hpp"

#include <filesystem>
#include <fstream>
#include <regex>

#include "core/path_check.hpp"
#include "external/client_process.hpp"
#include "external/sha256.hpp"

namespace omniloc::external {

namespace fs = std::filesystem;

namespace {

// Interpreters whose first non-option argument is the client's script (docs/protocol.md, section 2).
bool is_interpreter(const std::string& program) {
  static const std::regex re(R"((python[0-9.]*|perl|node|nodejs|bash|sh|dash|ruby|julia|Rscript|lua[0-9.]*|tclsh[0-9.]*))");
  return std::regex_match(fs::path(program).filename().string(), re);
}

// Index of an interpreter's script argument in `command`, or 0 when there is none (-m, -c, none).
std::size_t script_index(const std::vector<std::string>& command) {
  if (command.empty() || !is_interpreter(command[0])) return 0;
  for (std::size_t i = 1; i < command.size(); ++i) {
    const std::string& a = command[i];
    if (a == "-m" || a == "-c" || a == "-e" || a == "-E" || a == "--eval") return 0;
    if (a.empty() || a[0] != '-') return i;
  }
  return 0;
}

std::string absolute_from(const std::string& p, const std::string& base) {
  return fs::path(p).is_absolute() ? p : (fs::path(base) / p).lexically_normal().string();
}

}  // namespace

ExternalConfig ExternalConfig::from_json(JsonReader& r) {
  ExternalConfig c;
  c.command = r.strings("command", std::nullopt);
  const std::string cmd_path = r.child_path("command");
  if (c.command.empty()) throw ConfigError(cmd_path, "[]", "a non-empty array: the client program and its arguments");
  for (std::size_t i = 0; i < c.command.size(); ++i)
    if (c.command[i].empty() || c.command[i].find('\0') != std::string::npos)
      throw ConfigError(json_child(cmd_path, i), "\"\"", "a non-empty string");
  c.cwd = absolute_from(r.string("cwd", fs::current_path().string()), fs::current_path().string());
  require_readable_folder(c.cwd, r.child_path("cwd"), "an existing folder (the client's working directory)");
  if (const Json* p = r.raw("params")) {
    if (!p->is_object()) throw ConfigError(r.child_path("params"), json_brief(*p), "an object (passed to the client in hello.params)");
    c.params = *p;
  }
  if (const Json* e = r.raw("env")) {
    if (!e->is_object()) throw ConfigError(r.child_path("env"), json_brief(*e), "an object of strings {\"NAME\": \"value\"}");
    static const std::regex name_re("[A-Za-z_][A-Za-z0-9_]*");
    for (auto it = e->begin(); it != e->end(); ++it) {
      const std::string at = json_child(r.child_path("env"), it.key());
      if (!std::regex_match(it.key(), name_re)) throw ConfigError(at, "\"" + it.key() + "\"", "an environment variable name [A-Za-z_][A-Za-z0-9_]*");
      if (!it.value().is_string() || it.value().get<std::string>().find('\0') != std::string::npos)
        throw ConfigError(at, json_brief(it.value()), "a string");
      c.env[it.key()] = it.value().get<std::string>();
    }
  }
  c.hello_timeout_s = r.positive("hello_timeout_s", 60.0, 3600.0);
  c.frame_timeout_s = r.positive("frame_timeout_s", 10.0, 3600.0);
  c.exit_timeout_s = r.positive("exit_timeout_s", 5.0, 600.0);
  c.label = r.string("label", std::string());
  if (!c.label.empty() && !std::regex_match(c.label, std::regex("[A-Za-z0-9_.-]{1,64}")))
    throw ConfigError(r.child_path("label"), "\"" + c.label + "\"", "1-64 characters of [A-Za-z0-9_.-]");

  // Files the command does not name but the client runs (modules it imports, a model it loads).
  const std::vector<std::string> hash = r.strings("hash", std::vector<std::string>{});
  if (hash.size() > 256) throw ConfigError(r.child_path("hash"), std::to_string(hash.size()) + " files", "at most 256 files");
  for (std::size_t i = 0; i < hash.size(); ++i) {
    const std::string p = hash[i].empty() || hash[i].find('\0') != std::string::npos ? hash[i] : absolute_from(hash[i], c.cwd);
    require_readable_file(p, json_child(r.child_path("hash"), i),
                          "an existing file to record in provenance (relative paths are taken against " + c.cwd + ")");
    c.hash.push_back(p);
  }

  const auto program = resolve_program(c.command[0], c.cwd);
  if (!program) {
    const bool has_slash = c.command[0].find('/') != std::string::npos;
    // A path names one file: say what is wrong with it. A bare name was looked for on PATH.
    std::string why = has_slash ? why_not_readable_file(absolute_from(c.command[0], c.cwd)) : "not on PATH";
    if (why.empty()) why = "not executable";
    throw ConfigError(json_child(cmd_path, std::size_t{0}), path_value(c.command[0], why),
                      has_slash ? "an executable file (relative paths are taken against " + c.cwd + ")" : "an executable program on PATH");
  }
  c.program = *program;
  if (const std::size_t i = script_index(c.command); i > 0) {
    const std::string script = absolute_from(c.command[i], c.cwd);
    require_readable_file(script, json_child(cmd_path, i),
                          "an existing script file for " + fs::path(c.command[0]).filename().string() + " (relative paths are taken against " + c.cwd + ")");
  }
  return c;
}

Json ExternalConfig::schema() {
  auto num = [](const char* d, double def, double hi) {
    return Json{{"type", "number"}, {"exclusiveMinimum", 0}, {"maximum", hi}, {"default", def}, {"description", d}};
  };
  return {
      {"command", {{"type", "array"}, {"items", {{"type", "string"}, {"minLength", 1}}}, {"minItems", 1},
                   {"description", "the client program and its arguments, run without a shell (docs/protocol.md)"}}},
      {"cwd", {{"type", "string"}, {"description", "the client's working directory (default: omniloc's); relative paths in command are taken against it"}}},
      {"params", {{"type", "object"}, {"description", "passed unchanged to the client in hello.params"}}},
      {"env", {{"type", "object"}, {"additionalProperties", {{"type", "string"}}}, {"description", "extra environment variables for the client"}}},
      {"hello_timeout_s", num("seconds from starting the client to its ready message", 60, 3600)},
      {"frame_timeout_s", num("seconds from sending a frame to its estimate", 10, 3600)},
      {"exit_timeout_s", num("seconds from end to the client's exit", 5, 600)},
      {"label", {{"type", "string"}, {"pattern", "^[A-Za-z0-9_.-]{1,64}$"}, {"description", "the name results carry (default: the client's ready.name; a sweep's run folders: the script's file name)"}}},
      {"hash", {{"type", "array"}, {"items", {{"type", "string"}, {"minLength", 1}}}, {"maxItems", 256},
                {"description", "more files whose SHA-256 summary.json records beside the command's (the client's modules, models); relative to cwd"}}},
  };
}

void anchor_external_paths(Json& localizer) {
  if (!localizer.is_object() || localizer.value("type", Json()) != "external") return;
  const std::string here = fs::current_path().string();
  const auto it = localizer.find("cwd");
  if (it == localizer.end()) localizer["cwd"] = here;
  else if (it->is_string()) *it = absolute_from(it->get<std::string>(), here);
}

std::string default_label(const Json& localizer) {
  std::vector<std::string> command;
  if (const auto it = localizer.find("command"); it != localizer.end() && it->is_array())
    for (const auto& c : *it)
      if (c.is_string()) command.push_back(c.get<std::string>());
  if (command.empty()) return "external";
  const std::size_t i = script_index(command);
  std::string stem = fs::path(command[i]).stem().string();
  for (char& ch : stem)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '.' && ch != '-') ch = '_';
  return stem.empty() ? "external" : stem.substr(0, 64);
}

Json client_files(const ExternalConfig& cfg) {
  Json files = Json::array();
  files.push_back({{"path", cfg.program}, {"sha256", sha256_file(cfg.program)}});
  std::error_code ec;
  for (std::size_t i = 1; i < cfg.command.size(); ++i) {
    const std::string p = absolute_from(cfg.command[i], cfg.cwd);
    if (cfg.command[i][0] != '-' && fs::is_regular_file(p, ec)) files.push_back({{"path", p}, {"sha256", sha256_file(p)}});
  }
  for (const auto& p : cfg.hash) files.push_back({{"path", p}, {"sha256", sha256_file(p)}});
  return files;
}

Json describe_client(const Json& localizer) {
  if (!localizer.is_object() || localizer.value("type", Json()) != "external") return nullptr;
  JsonReader r(localizer, "/localizer");
  const ExternalConfig cfg = ExternalConfig::from_json(r);
  return {{"command", cfg.command}, {"cwd", cfg.cwd}, {"files", client_files(cfg)}};
}

}  // namespace omniloc::external
