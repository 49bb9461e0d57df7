// omniloc command line: finds the command in the table (apps/commands.cpp) and runs it.
// Exit codes: 0 success, 1 runtime failure, 2 bad input (scenario, arguments) — nothing written.
#include <algorithm>
#include <iostream>
#include <string>

#include "apps/command_support.hpp"
#include "apps/commands.hpp"
#include "core/error.hpp"
#include "core/version.hpp"

using namespace omniloc;

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << app::usage_text();
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  if (cmd == "--version" || cmd == "version") {
    std::cout << version_line() << "\n";
    return 0;
  }
  const auto& table = app::commands();
  const auto c = std::find_if(table.begin(), table.end(), [&](const app::CommandEntry& e) { return e.name == cmd; });
  if (c != table.end() && c->python) {
    std::string module = cmd;
    std::replace(module.begin(), module.end(), '-', '_');
    return app::exec_python_module(module, "omniloc " + cmd, argc, argv);
  }
  try {
    if (c == table.end()) {
      std::cerr << "error: unknown command \"" << cmd << "\"\n" << app::usage_text();
      return 2;
    }
    cli::Args a = cli::parse(*c->options, argc, argv, 2);
    if (a.help) {
      std::cout << cli::help_text(*c->options);
      return 0;
    }
    // The one place input files of these commands are named: shipped ones are found from anywhere.
    if (c->shipped_inputs)
      for (auto& file : a.positional) file = app::shipped_or_given(file);
    return c->run(a);
  } catch (const ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const cli::UsageError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "failed: " << e.what() << "\n";
    return 1;
  }
}
