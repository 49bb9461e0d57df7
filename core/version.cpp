#include "core/version.hpp"

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

std::string version_line() {
  const BuildInfo& b = build_info();
  return "omniloc " + b.version + " (" + b.compiler + ", " + b.build_type + ")";
}

}  // namespace omniloc
