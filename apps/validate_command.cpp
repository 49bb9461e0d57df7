// `omniloc validate`: scenario, sweep and experiment description files checked without running.
#include "apps/commands.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "apps/command_support.hpp"
#include "batch/sweep_spec.hpp"
#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "experiments/experiment.hpp"
#include "harness/scenario.hpp"

namespace omniloc::app {

const cli::Command kValidate{"validate", "FILE...", 1, 1000000,
                             "Check scenario, sweep or experiment description files without running anything;\n"
                             "exit 2 with the JSON path of the first problem. With several files each is checked in\n"
                             "its own process and a line \"[exit N] FILE\" (or \"[signal S] FILE\") follows it; the exit\n"
                             "code is then 0 when all passed, 2 when some had input errors, 1 when any failed otherwise.",
                             {}};

namespace {

int validate_one(const std::string& file) {
  // The strict reader first: depth, size, duplicate keys, NUL bytes, numbers out of range.
  const Json j = read_json_strict(file, file);
  // An experiment description (scenarios/experiments/*.json) names its experiment; the experiment checks it.
  {
    if (j.is_object() && j.contains("experiment") && j["experiment"].is_string()) {
      for (const auto& e : experiments::all())
        if (e.name == j["experiment"].get<std::string>() && e.validate) {
          e.validate(file);
          std::cout << file << ": ok (description of experiment \"" << e.name << "\")\n";
          return 0;
        }
      throw ConfigError("/experiment", json_brief(j["experiment"]), "the name of an experiment that reads a description file (see omniloc list)");
    }
  }
  // A sweep file lists scenarios (and has no robots of its own): every combination is validated.
  if (j.is_object() && j.contains("scenarios") && !j.contains("robots")) {
    const auto spec = batch::load_sweep(file);
    std::cout << file << ": ok (sweep \"" << spec.name << "\", " << spec.runs.size() << " run(s))\n";
    return 0;
  }
  const auto s = harness::parse_scenario(j, std::filesystem::path(file).stem().string(), file);
  std::cout << file << ": ok (scenario \"" << s.name << "\", " << s.robots.size() << " robot(s), "
            << s.duration << " s, localizer " << s.localizer.json.value("type", "?") << ")\n";
  return 0;
}

// The same exit codes as main() for one file.
int validate_one_guarded(const std::string& file) {
  try {
    return validate_one(file);
  } catch (const ConfigError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "failed: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

int cmd_validate(const cli::Args& a) {
  if (a.positional.size() == 1) return validate_one(a.positional[0]);
  // Several files: each in a forked child, so one crashing input cannot hide the verdict on the
  // others and is reported as the signal it died of (the mutation test drives thousands this way
  // without paying the program's start-up, ~0.2 s of shared-library loading, per file).
  int worst = 0;
  for (const auto& file : a.positional) {
    std::cout.flush();
    std::cerr.flush();
    const pid_t pid = ::fork();
    if (pid < 0) throw RuntimeFailure(std::string("cannot fork: ") + std::strerror(errno));
    if (pid == 0) {
      const int code = validate_one_guarded(file);
      std::cout.flush();
      std::cerr.flush();
      ::_exit(code);
    }
    int st = 0;
    while (::waitpid(pid, &st, 0) < 0 && errno == EINTR) {
    }
    if (WIFSIGNALED(st)) {
      std::cout << "[signal " << WTERMSIG(st) << "] " << file << "\n";
      worst = 1;
    } else {
      const int code = WIFEXITED(st) ? WEXITSTATUS(st) : 1;
      std::cout << "[exit " << code << "] " << file << "\n";
      if (code != 0 && code != 2) worst = 1;
      else if (code == 2 && worst == 0) worst = 2;
    }
  }
  return worst;
}

}  // namespace omniloc::app
