#include "core/version.hpp"

#include <fstream>
#include <thread>

#include "omniloc_version.hpp"  // generated into the build folder by cmake/version.cmake

namespace omniloc {

const BuildInfo& build_info() {
  static const BuildInfo info{OMNILOC_GIT_DESCRIBE, OMNILOC_COMPILER, OMNILOC_BUILD_TYPE};
  return info;
}

Json build_info_json() {
  const BuildInfo& b = build_info();
  return Json{{"version", b.version}, {"compiler", b.compiler}, {"build_type", b.build_type}};
}

Json host_info_json() {
  std::string cpu = "unknown";
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      cpu = line.substr(line.find(':') + 1);
      cpu.erase(0, cpu.find_first_not_of(" \t"));
      break;
    }
  return Json{{"cpu", cpu}, {"cores", std::thread::hardware_concurrency()}};
}

std::string version_line() {
  const BuildInfo& b = build_info();
  return "omniloc " + b.version + " (" + b.compiler + ", " + b.build_type + ")";
}

}  // namespace omniloc
