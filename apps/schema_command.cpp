// `omniloc schema`: the JSON Schema of scenario or sweep files, or the parameter reference.
#include "apps/commands.hpp"

#include <iostream>

#include "apps/command_support.hpp"
#include "batch/sweep_spec.hpp"
#include "core/atomic_file.hpp"
#include "core/path_check.hpp"
#include "harness/scenario_schema.hpp"

namespace omniloc::app {

const cli::Command kSchema{"schema", "", 0, 0, "The JSON Schema of scenario files (or of sweep files), or (--markdown) the parameter reference docs/localizers.md.",
                           {{"--markdown", "", "the parameter reference instead of the schema"},
                            {"--sweep", "", "the JSON Schema of sweep files instead"},
                            {"-o", "FILE", "write to FILE (atomically) instead of standard output"}}};

int cmd_schema(const cli::Args& a) {
  if (a.has("--markdown") && a.has("--sweep")) throw UsageError("--markdown and --sweep: choose one");
  const std::string text = a.has("--markdown") ? harness::parameter_reference()
                           : a.has("--sweep")  ? batch::sweep_schema().dump(2) + "\n"
                                               : harness::scenario_schema().dump(2) + "\n";
  const std::string out = a.value("-o");
  if (!out.empty()) require_writable(out, "-o", false);
  if (out.empty()) {
    std::cout << text;
  } else {
    write_file_atomic(out, text);
    std::cerr << "wrote " << out << "\n";
  }
  return 0;
}

}  // namespace omniloc::app
