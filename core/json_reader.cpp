#include "core/json_reader.hpp"

#include <cmath>
#include <iterator>
#include <sstream>
#include <vector>

namespace omniloc {

namespace {
std::string fmt_number(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}
std::string range_text(double lo, double hi, bool open_lo = false) {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) return std::string(open_lo ? "a number in (" : "a number in [") + fmt_number(lo) + ", " + fmt_number(hi) + "]";
  if (has_lo) return std::string(open_lo ? "a number > " : "a number >= ") + fmt_number(lo);
  if (has_hi) return "a number <= " + fmt_number(hi);
  return "a number";
}
}  // namespace

ConfigError::ConfigError(std::string path, std::string value, std::string expected)
    : std::runtime_error((path.empty() ? std::string("/") : path) + ": got " + value + ", expected " + expected),
      path_(std::move(path)),
      value_(std::move(value)),
      expected_(std::move(expected)) {}

// Renders at most ~60 characters without recursion and without serialising the whole value: an
// error message about a 16 MiB array must not cost a 16 MiB dump, and a value built in code may be
// nested deeper than the parser allows. Invalid UTF-8 is replaced rather than thrown on (dump()
// would throw type_error 316 and turn a bad input into a crash-like exit 1).
std::string json_brief(const Json& v) {
  constexpr std::size_t kMax = 60;
  std::string s;
  struct Item {
    const Json* node;
    std::size_t next;  // index of the next child to render
  };
  std::vector<Item> stack;
  auto scalar = [&](const Json& x) {
    if (x.is_string() && x.get_ref<const std::string&>().size() > kMax) {
      const std::string& str = x.get_ref<const std::string&>();
      s += Json(str.substr(0, kMax)).dump(-1, ' ', false, Json::error_handler_t::replace);
    } else {
      s += x.dump(-1, ' ', false, Json::error_handler_t::replace);
    }
  };
  auto begin = [&](const Json& x) {
    if (x.is_object()) s += '{', stack.push_back({&x, 0});
    else if (x.is_array()) s += '[', stack.push_back({&x, 0});
    else scalar(x);
  };
  begin(v);
  while (!stack.empty() && s.size() <= kMax) {
    Item& it = stack.back();
    const Json& node = *it.node;
    if (it.next >= node.size()) {
      s += node.is_object() ? '}' : ']';
      stack.pop_back();
      continue;
    }
    if (it.next > 0) s += ',';
    if (node.is_object()) {
      auto e = node.begin();
      std::advance(e, static_cast<std::ptrdiff_t>(it.next));  // linear, but only while s is short
      ++it.next;
      s += Json(e.key()).dump(-1, ' ', false, Json::error_handler_t::replace) + ':';
      begin(e.value());
    } else {
      const Json& child = node[it.next];
      ++it.next;
      begin(child);
    }
  }
  if (s.size() > kMax) s = s.substr(0, kMax - 3) + "...";
  return s;
}

std::string json_child(const std::string& path, const std::string& key) {
  std::string k;
  for (char c : key) {  // RFC 6901 escaping
    if (c == '~') k += "~0";
    else if (c == '/') k += "~1";
    else k += c;
  }
  return path + "/" + k;
}

std::string json_child(const std::string& path, std::size_t index) { return path + "/" + std::to_string(index); }

JsonReader::JsonReader(const Json& j, std::string path, Json* effective)
    : j_(j), effective_(effective), path_(std::move(path)) {
  if (!j_.is_object()) throw ConfigError(path_, json_brief(j_), "an object");
  if (effective_ && !effective_->is_object()) *effective_ = Json::object();
}

bool JsonReader::has(const std::string& key) const { return j_.contains(key); }
void JsonReader::allow(const std::string& key) { seen_.insert(key); }

const Json* JsonReader::fetch(const std::string& key, bool required) {
  seen_.insert(key);
  auto it = j_.find(key);
  if (it == j_.end()) {
    if (required) throw ConfigError(child_path(key), "nothing (missing key)", "a value for required key \"" + key + "\"");
    return nullptr;
  }
  return &*it;
}

const Json* JsonReader::raw(const std::string& key, bool required) {
  const Json* v = fetch(key, required);
  if (v) record(key, *v);
  return v;
}

double JsonReader::number(const std::string& key, std::optional<double> def, double lo, double hi) {
  const Json* v = fetch(key, !def.has_value());
  if (!v) {
    record(key, *def);
    return *def;
  }
  if (!v->is_number()) throw ConfigError(child_path(key), json_brief(*v), range_text(lo, hi));
  const double d = v->get<double>();
  if (!std::isfinite(d) || d < lo || d > hi) throw ConfigError(child_path(key), json_brief(*v), range_text(lo, hi));
  record(key, d);
  return d;
}

double JsonReader::positive(const std::string& key, std::optional<double> def, double hi) {
  const Json* v = fetch(key, !def.has_value());
  if (!v) {
    record(key, *def);
    return *def;
  }
  if (!v->is_number()) throw ConfigError(child_path(key), json_brief(*v), range_text(0, hi, true));
  const double d = v->get<double>();
  if (!std::isfinite(d) || d <= 0.0 || d > hi) throw ConfigError(child_path(key), json_brief(*v), range_text(0, hi, true));
  record(key, d);
  return d;
}

long long JsonReader::integer(const std::string& key, std::optional<long long> def, long long lo, long long hi) {
  const Json* v = fetch(key, !def.has_value());
  if (!v) {
    record(key, *def);
    return *def;
  }
  auto expected = [&] {
    std::string e = "an integer";
    if (lo != std::numeric_limits<long long>::min() && hi != std::numeric_limits<long long>::max())
      e += " in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    else if (lo != std::numeric_limits<long long>::min())
      e += " >= " + std::to_string(lo);
    else if (hi != std::numeric_limits<long long>::max())
      e += " <= " + std::to_string(hi);
    return e;
  };
  long long x;
  if (v->is_number_integer()) {
    x = v->get<long long>();
  } else if (v->is_number_float() && std::floor(v->get<double>()) == v->get<double>() && std::fabs(v->get<double>()) < 9e15) {
    x = static_cast<long long>(v->get<double>());
  } else {
    throw ConfigError(child_path(key), json_brief(*v), expected());
  }
  if (x < lo || x > hi) throw ConfigError(child_path(key), json_brief(*v), expected());
  record(key, x);
  return x;
}

bool JsonReader::boolean(const std::string& key, std::optional<bool> def) {
  const Json* v = fetch(key, !def.has_value());
  if (!v) {
    record(key, *def);
    return *def;
  }
  if (!v->is_boolean()) throw ConfigError(child_path(key), json_brief(*v), "true or false");
  record(key, v->get<bool>());
  return v->get<bool>();
}

std::vector<std::string> JsonReader::strings(const std::string& key, std::optional<std::vector<std::string>> def,
                                             const std::vector<std::string>& allowed) {
  const Json* v = fetch(key, !def.has_value());
  auto expected = [&] {
    if (allowed.empty()) return std::string("an array of strings");
    std::string e = "an array of strings, each one of ";
    for (std::size_t i = 0; i < allowed.size(); ++i) e += (i ? ", \"" : "\"") + allowed[i] + "\"";
    return e;
  };
  if (!v) {
    record(key, *def);
    return *def;
  }
  if (!v->is_array()) throw ConfigError(child_path(key), json_brief(*v), expected());
  std::vector<std::string> out;
  for (std::size_t i = 0; i < v->size(); ++i) {
    const Json& e = (*v)[i];
    bool ok = e.is_string();
    if (ok && !allowed.empty()) {
      ok = false;
      for (const auto& a : allowed) ok = ok || a == e.get<std::string>();
    }
    if (!ok) throw ConfigError(json_child(child_path(key), i), json_brief(e), expected());
    out.push_back(e.get<std::string>());
  }
  record(key, out);
  return out;
}

std::string JsonReader::string(const std::string& key, std::optional<std::string> def,
                               const std::vector<std::string>& allowed) {
  const Json* v = fetch(key, !def.has_value());
  auto expected = [&] {
    if (allowed.empty()) return std::string("a string");
    std::string e = "one of ";
    for (std::size_t i = 0; i < allowed.size(); ++i) e += (i ? ", \"" : "\"") + allowed[i] + "\"";
    return e;
  };
  if (!v) {
    record(key, *def);
    return *def;
  }
  if (!v->is_string()) throw ConfigError(child_path(key), json_brief(*v), expected());
  std::string s = v->get<std::string>();
  if (!allowed.empty()) {
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == s;
    if (!ok) throw ConfigError(child_path(key), json_brief(*v), expected());
  }
  record(key, s);
  return s;
}

std::vector<double> JsonReader::numbers(const std::string& key, std::optional<std::vector<double>> def,
                                        std::size_t length) {
  const Json* v = fetch(key, !def.has_value());
  if (!v) {
    record(key, *def);
    return *def;
  }
  const std::string expected = "an array of " + std::to_string(length) + " numbers";
  if (!v->is_array() || v->size() != length) throw ConfigError(child_path(key), json_brief(*v), expected);
  std::vector<double> out;
  for (std::size_t i = 0; i < length; ++i) {
    const Json& e = (*v)[i];
    if (!e.is_number() || !std::isfinite(e.get<double>()))
      throw ConfigError(json_child(child_path(key), i), json_brief(e), "a finite number");
    out.push_back(e.get<double>());
  }
  record(key, out);
  return out;
}

std::optional<JsonReader> JsonReader::object(const std::string& key, bool required) {
  const Json* v = fetch(key, required);
  if (!v) return std::nullopt;
  return JsonReader(*v, child_path(key), effective_ ? &(*effective_)[key] : nullptr);
}

void JsonReader::finish() const {
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    if (!seen_.count(it.key())) {
      std::string known;
      for (const auto& k : seen_) known += (known.empty() ? "" : ", ") + k;
      throw ConfigError(child_path(it.key()), "unknown key \"" + it.key() + "\"",
                        known.empty() ? std::string("no keys here") : "one of the known keys: " + known);
    }
  }
}

}  // namespace omniloc
