#pragma once
// The scenario key "localizer": {"type": "external", ...} (docs/protocol.md, section 2): read
// strictly, paths anchored, the program checked before any work, and what identifies the client
// (its files' SHA-256) for summary.json.
#include <map>
#include <string>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc::external {

struct ExternalConfig {
  std::vector<std::string> command;          ///< program and arguments, no shell
  std::string cwd;                           ///< the client's working directory (absolute once anchored)
  Json params = Json::object();              ///< passed through in hello.params
  std::map<std::string, std::string> env;    ///< extra environment variables
  double hello_timeout_s = 60.0;             ///< seconds from start to ready
  double frame_timeout_s = 10.0;             ///< seconds from sending a frame to its estimate
  double exit_timeout_s = 5.0;               ///< seconds from end to the client's exit
  std::string label;                         ///< the name results carry (default: ready.name; run folders: the script's stem)
  std::vector<std::string> hash;             ///< more files whose SHA-256 provenance records (the client's modules), absolute
  std::string program;                       ///< command[0] resolved (PATH or cwd), absolute

  /// Reads the keys at `r` ("type" already read) and checks that the program can be started:
  /// command[0] an executable file, an interpreter's script an existing file, cwd a folder.
  /// Throws ConfigError naming the JSON path.
  static ExternalConfig from_json(JsonReader& r);
  /// JSON Schema properties of the keys (for `omniloc schema` and docs/localizers.md).
  static Json schema();
};

/// When `localizer` is {"type": "external", ...}, makes its "cwd" absolute (against the current
/// working directory; absent: the current working directory itself), so per-run copies of the
/// scenario (sweeps, Slurm tasks) start the client where the user meant. Other localizers unchanged.
void anchor_external_paths(Json& localizer);

/// The label of an external localizer in a sweep when none is given: the file name, without
/// extension, of the first command element after an interpreter that names a script (else of
/// command[0]), restricted to [A-Za-z0-9_.-].
std::string default_label(const Json& localizer);

/// {"path", "sha256"} for the program, for every later command element that names an existing
/// regular file (relative ones against cwd) and for every file of "hash": what identifies the
/// client that made a result.
Json client_files(const ExternalConfig& cfg);

/// {"command", "cwd", "files"} of an external localizer object as a scenario holds it (checked
/// before), for records that describe many runs (slurm/submission.json); null for other types.
Json describe_client(const Json& localizer);

}  // namespace omniloc::external
