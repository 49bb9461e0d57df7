#pragma once
// printf-style formatting into a std::string, for the experiments' text tables.
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

namespace omniloc::experiments {

/// `f` with `a...` as std::snprintf would print them, cut at 511 characters.
template <class... A>
std::string strprintf(const char* f, A... a) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

/// "<CPU model>, <n> hardware threads": the machine a table was measured on.
inline std::string machine_text() {
  std::string model = "unknown CPU";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

}  // namespace omniloc::experiments
