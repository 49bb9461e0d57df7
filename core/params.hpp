#pragma once
// One list per parameter struct: each field's JSON key, the member it fills, its range, unit and
// meaning, written once. The list drives strict JSON reading (JsonReader, so errors name the JSON
// path and the effective configuration records every value, defaults included), the JSON Schema of
// scenario files (`omniloc schema`), and through it the generated parameter reference
// (docs/localizers.md).
// After Drake's camera_config.h: one field list with Serialize and ValidateOrThrow.
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc {

enum class ParamKind {
  kNumber,    ///< a number in [lo, hi]
  kPositive,  ///< a number in (0, hi]
  kInteger,   ///< an integer in [lo, hi]
  kBoolean,
};

template <class T>
struct Param {
  const char* key;
  std::variant<double T::*, int T::*, bool T::*> member;
  ParamKind kind;
  double lo, hi;
  const char* unit;  ///< "m", "rad", "s", "px", "" (a count or a ratio)
  const char* doc;   ///< one line: what it is and, where it comes from a paper, which
};

template <class T>
using ParamList = std::vector<Param<T>>;

// Row makers, so a list reads like a table.
template <class T>
Param<T> number_param(const char* key, double T::*m, double lo, double hi, const char* unit, const char* doc) {
  return {key, m, ParamKind::kNumber, lo, hi, unit, doc};
}
template <class T>
Param<T> positive_param(const char* key, double T::*m, double hi, const char* unit, const char* doc) {
  return {key, m, ParamKind::kPositive, 0.0, hi, unit, doc};
}
template <class T>
Param<T> integer_param(const char* key, int T::*m, int lo, int hi, const char* doc) {
  return {key, m, ParamKind::kInteger, static_cast<double>(lo), static_cast<double>(hi), "", doc};
}
template <class T>
Param<T> bool_param(const char* key, bool T::*m, const char* doc) {
  return {key, m, ParamKind::kBoolean, 0.0, 0.0, "", doc};
}

/// Reads every listed key into `p` (absent keys keep p's value, which is the default), in list order.
template <class T>
void read_params(JsonReader& r, T& p, const ParamList<T>& list) {
  for (const auto& q : list) {
    switch (q.kind) {
      case ParamKind::kNumber: p.*std::get<double T::*>(q.member) = r.number(q.key, p.*std::get<double T::*>(q.member), q.lo, q.hi); break;
      case ParamKind::kPositive: p.*std::get<double T::*>(q.member) = r.positive(q.key, p.*std::get<double T::*>(q.member), q.hi); break;
      case ParamKind::kInteger: {
        int& v = p.*std::get<int T::*>(q.member);
        v = static_cast<int>(r.integer(q.key, v, static_cast<long long>(q.lo), static_cast<long long>(q.hi)));
        break;
      }
      case ParamKind::kBoolean: p.*std::get<bool T::*>(q.member) = r.boolean(q.key, p.*std::get<bool T::*>(q.member)); break;
    }
  }
}

/// Reads the one listed parameter `key` (for a default that depends on it, e.g. matching's c_start).
template <class T>
void read_param(JsonReader& r, T& p, const ParamList<T>& list, const char* key) {
  for (const auto& q : list)
    if (std::string(q.key) == key) {
      read_params(r, p, ParamList<T>{q});
      return;
    }
}

/// The value of one parameter of `p` as JSON.
template <class T>
Json param_value(const Param<T>& q, const T& p) {
  return std::visit([&](auto m) { return Json(p.*m); }, q.member);
}

/// JSON Schema properties {key: {type, minimum / exclusiveMinimum, maximum, default, description}}.
template <class T>
Json params_schema(const ParamList<T>& list, const T& defaults = T{}) {
  Json props = Json::object();
  for (const auto& q : list) {
    Json s;
    s["default"] = param_value(q, defaults);
    const std::string unit = q.unit[0] ? std::string(" [") + q.unit + "]" : std::string();
    s["description"] = std::string(q.doc) + unit;
    switch (q.kind) {
      case ParamKind::kBoolean: s["type"] = "boolean"; break;
      case ParamKind::kInteger: s["type"] = "integer"; s["minimum"] = static_cast<long long>(q.lo); s["maximum"] = static_cast<long long>(q.hi); break;
      case ParamKind::kPositive: s["type"] = "number"; s["exclusiveMinimum"] = 0; break;
      case ParamKind::kNumber: s["type"] = "number"; break;
    }
    if (q.kind == ParamKind::kNumber && q.lo > -std::numeric_limits<double>::max()) s["minimum"] = q.lo;
    if ((q.kind == ParamKind::kNumber || q.kind == ParamKind::kPositive) && q.hi < std::numeric_limits<double>::max()) s["maximum"] = q.hi;
    props[q.key] = s;
  }
  return props;
}

}  // namespace omniloc
