#pragma once
// Every command of `omniloc`, in one table (commands.cpp): its name, the lines `omniloc --help` shows
// for it and how it runs. A command written in C++ is one file here with its option table and its
// body, declared below; a command of the Python results package is one table line and nothing else.
#include <string>
#include <vector>

#include "core/cli_args.hpp"

namespace omniloc::app {

/// One form of a command as `omniloc --help` lists it: the arguments after the name (a "\n" starts
/// a continuation line) and what it does (lines of up to about 80 characters, "\n" between them).
struct Usage {
  std::string synopsis;
  std::string does;
};

struct CommandEntry {
  std::string name;
  std::vector<Usage> usage;
  /// A C++ command: its options (cli::parse reads the command line against them) and its body.
  const cli::Command* options = nullptr;
  int (*run)(const cli::Args&) = nullptr;
  /// Its positional arguments are input files that may be shipped ones (shipped_or_given).
  bool shipped_inputs = false;
  /// A command of the results package: python/omniloc/commands/<name, '-' as '_'>.py gets the
  /// command line as it is (its own --help and errors).
  bool python = false;
};

/// In the order `omniloc --help` lists them.
const std::vector<CommandEntry>& commands();

/// What `omniloc --help` prints (and `omniloc` alone, or an unknown command, on stderr).
std::string usage_text();

/// Runs `omniloc <prog>`'s Python module with argv[2..]; returns only when the interpreter cannot
/// be started.
int exec_python_module(const std::string& module, const std::string& prog, int argc, char** argv);

// The C++ commands, each in its file: its option table (`omniloc CMD --help` prints it, the parser
// accepts exactly these options; adding an option is adding a row and reading it in the body) and body.
extern const cli::Command kRun, kRecord, kReplay, kRender, kCalibrate, kColourCalibrate, kValidate, kGlDevices, kList, kSchema,
    kSweep, kExperiment, kCache;
int cmd_run(const cli::Args& a);
int cmd_record(const cli::Args& a);
int cmd_replay(const cli::Args& a);
int cmd_render(const cli::Args& a);
int cmd_calibrate(const cli::Args& a);
int cmd_colour_calibrate(const cli::Args& a);
int cmd_validate(const cli::Args& a);
int cmd_gl_devices(const cli::Args& a);
int cmd_list(const cli::Args& a);
int cmd_schema(const cli::Args& a);
int cmd_sweep(const cli::Args& a);
int cmd_experiment(const cli::Args& a);
int cmd_cache(const cli::Args& a);

}  // namespace omniloc::app
