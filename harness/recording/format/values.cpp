#include "harness/recording/format/values.hpp"

#include <cmath>
#include <cstdio>

#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "harness/recording/format/limits.hpp"

namespace omniloc::harness::recording_values {

using namespace recording_limits;  // docs/recording.md section 7

Json pose_json(const Pose2& p) { return Json::array({p.x, p.y, p.theta}); }

[[noreturn]] void bad(const std::string& at, const Json& v, const std::string& expected) { throw ConfigError(at, json_brief(v), expected); }

const Json& member(const Json& o, const char* key, const std::string& at) {
  const auto it = o.find(key);
  if (it == o.end()) throw ConfigError(json_child(at, key), "nothing", "a value (docs/recording.md)");
  return *it;
}

double finite(const Json& v, const std::string& at) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) bad(at, v, "a finite number");
  return v.get<double>();
}

double within(const Json& v, const std::string& at, double lo, double hi, const char* unit) {
  const double x = finite(v, at);
  if (x < lo || x > hi) {
    char range[160];
    std::snprintf(range, sizeof range, "a number from %g to %g %s (docs/recording.md section 7)", lo, hi, unit);
    bad(at, v, range);
  }
  return x;
}
double length(const Json& v, const std::string& at) { return within(v, at, -kMaxLength, kMaxLength, "m"); }
double angle(const Json& v, const std::string& at) { return within(v, at, -kMaxAngle, kMaxAngle, "rad"); }

bool boolean(const Json& v, const std::string& at) {
  if (!v.is_boolean()) bad(at, v, "true or false");
  return v.get<bool>();
}

Pose2 pose(const Json& v, const std::string& at) {
  if (!v.is_array() || v.size() != 3) bad(at, v, "[x, y, theta]");
  return Pose2(length(v[0], json_child(at, std::size_t{0})), length(v[1], json_child(at, std::size_t{1})), angle(v[2], json_child(at, std::size_t{2})));
}

}  // namespace omniloc::harness::recording_values
