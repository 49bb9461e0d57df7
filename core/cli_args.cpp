#include "core/cli_args.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace omniloc::cli {

namespace {
const Option* find(const Command& cmd, const std::string& name) {
  for (const auto& o : cmd.options)
    if (o.name == name) return &o;
  return nullptr;
}
}  // namespace

bool parse_int(const std::string& s, long long& out) {
  const char* b = s.data();
  const char* e = s.data() + s.size();
  const auto r = std::from_chars(b, e, out);
  return !s.empty() && r.ec == std::errc() && r.ptr == e;
}

bool parse_uint(const std::string& s, std::uint64_t& out) {
  // from_chars for an unsigned type rejects a leading '-' (strtoull would wrap "-1" to 2^64 - 1).
  const char* b = s.data();
  const char* e = s.data() + s.size();
  const auto r = std::from_chars(b, e, out);
  return !s.empty() && r.ec == std::errc() && r.ptr == e;
}

bool parse_double(const std::string& s, double& out) {
  const char* b = s.data();
  const char* e = s.data() + s.size();
  const auto r = std::from_chars(b, e, out);  // no leading spaces, no trailing text, "nan" is caught below
  return !s.empty() && r.ec == std::errc() && r.ptr == e && std::isfinite(out);
}

bool Args::has(const std::string& name) const {
  for (const auto& f : flags)
    if (f == name) return true;
  for (const auto& [k, v] : values)
    if (k == name) return true;
  return false;
}

std::string Args::value(const std::string& name, const std::string& def) const {
  std::string out = def;
  for (const auto& [k, v] : values)
    if (k == name) out = v;
  return out;
}

long long Args::integer(const std::string& name, long long def, long long lo, long long hi) const {
  if (!has(name)) return def;
  const std::string s = value(name);
  long long v = 0;
  if (!parse_int(s, v) || v < lo || v > hi)
    throw UsageError(name + " needs an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got \"" + s + "\"");
  return v;
}

std::uint64_t Args::unsigned_integer(const std::string& name, std::uint64_t def, std::uint64_t hi) const {
  if (!has(name)) return def;
  const std::string s = value(name);
  std::uint64_t v = 0;
  if (!parse_uint(s, v) || v > hi)
    throw UsageError(name + " needs an integer in [0, " + std::to_string(hi) + "], got \"" + s + "\"");
  return v;
}

double Args::number(const std::string& name, double def, double lo, double hi) const {
  if (!has(name)) return def;
  const std::string s = value(name);
  double v = 0;
  if (!parse_double(s, v) || v < lo || v > hi) {
    char range[96];
    std::snprintf(range, sizeof range, "[%g, %g]", lo, hi);
    throw UsageError(name + " needs a number in " + range + ", got \"" + s + "\"");
  }
  return v;
}

Args parse(const Command& cmd, int argc, char** argv, int first) {
  Args a;
  for (int i = first; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--help" || s == "-h") {
      a.help = true;
      continue;
    }
    if (s.size() > 1 && s[0] == '-') {
      std::string name = s, inline_value;
      bool has_inline = false;
      if (const auto eq = s.find('='); eq != std::string::npos && s.rfind("--", 0) == 0) {
        name = s.substr(0, eq);
        inline_value = s.substr(eq + 1);
        has_inline = true;
      }
      const Option* o = find(cmd, name);
      if (!o) throw UsageError("unknown option " + name + " for " + cmd.name + " (see omniloc " + cmd.name + " --help)");
      if (o->value_name.empty()) {
        if (has_inline) throw UsageError("option " + name + " takes no value");
        a.flags.push_back(name);
      } else if (has_inline) {
        a.values.emplace_back(name, inline_value);
      } else {
        if (i + 1 >= argc) throw UsageError("option " + name + " needs a value (" + o->value_name + ")");
        a.values.emplace_back(name, argv[++i]);
      }
      continue;
    }
    a.positional.push_back(s);
  }
  if (a.help) return a;
  if (a.positional.size() < cmd.min_positional || a.positional.size() > cmd.max_positional) {
    std::string want = cmd.arguments.empty() ? "no arguments" : cmd.arguments;
    throw UsageError(cmd.name + " takes " + want + ", got " + std::to_string(a.positional.size()) + " argument(s)");
  }
  return a;
}

std::string help_text(const Command& cmd) {
  std::string s = "usage: omniloc " + cmd.name + (cmd.arguments.empty() ? "" : " " + cmd.arguments) +
                  (cmd.options.empty() ? "" : " [options]") + "\n\n" + cmd.summary + "\n";
  if (!cmd.options.empty()) s += "\noptions:\n";
  for (const auto& o : cmd.options) {
    std::string left = "  " + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
    if (left.size() < 24) left += std::string(24 - left.size(), ' ');
    else left += "\n" + std::string(24, ' ');
    s += left + o.help + "\n";
  }
  s += "  --help, -h            this text\n";
  return s;
}

}  // namespace omniloc::cli
