#pragma once
// printf-style formatting into a std::string, for the experiments' text tables.
#include <cstdio>
#include <string>

namespace omniloc::harness {

/// `f` with `a...` as std::snprintf would print them, cut at 511 characters.
template <class... A>
std::string strprintf(const char* f, A... a) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

}  // namespace omniloc::harness
