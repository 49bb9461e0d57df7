#include "batch/aggregate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <set>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/version.hpp"

namespace omniloc::batch {

namespace fs = std::filesystem;

namespace {

// Student t 0.975 quantiles for 1..30 degrees of freedom (the values python/omniloc/core/stats.py's
// t_quantile_975 computes), then the Cornish-Fisher expansion (within 2e-6 of them above 30).
double t975(std::size_t df) {
  static const double t[] = {0,        12.706205, 4.302653, 3.182446, 2.776445, 2.570582, 2.446912, 2.364624,
                             2.306004, 2.262157,  2.228139, 2.200985, 2.178813, 2.160369, 2.144787, 2.131450,
                             2.119905, 2.109816,  2.100922, 2.093024, 2.085963, 2.079614, 2.073873, 2.068658,
                             2.063899, 2.059539,  2.055529, 2.051831, 2.048407, 2.045230, 2.042272};
  if (df <= 30) return t[df];
  const double z = 1.959964, d = static_cast<double>(df);
  return z + (z * z * z + z) / (4 * d) + (5 * std::pow(z, 5) + 16 * z * z * z + 3 * z) / (96 * d * d) +
         (3 * std::pow(z, 7) + 19 * std::pow(z, 5) + 17 * z * z * z - 15 * z) / (384 * d * d * d);
}

// Metrics that are shares of frames or episodes, within [0, 1]: recall at a threshold, the share
// of frames answered, of kidnaps recovered.
bool is_fraction(const std::string& metric) {
  const auto ends = [&](const std::string& tail) { return metric.size() >= tail.size() && metric.compare(metric.size() - tail.size(), tail.size(), tail) == 0; };
  return metric.find("/recall/") != std::string::npos || metric.rfind("recall/", 0) == 0 || ends("valid_fraction") || ends("recovered_fraction") ||
         ends("/share");
}

// A run's metrics: its numbers by path ("r0/position_m/rmse"), and the paths whose value is null (a
// statistic over no frame: no estimate), which a group counts instead of averaging.
struct RunMetrics {
  std::map<std::string, double> values;
  std::set<std::string> nulls;
};

void flatten(const Json& j, const std::string& prefix, RunMetrics& out) {
  if (j.is_number()) {
    out.values[prefix] = j.get<double>();
  } else if (j.is_null()) {
    out.nulls.insert(prefix);
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) flatten(it.value(), prefix.empty() ? it.key() : prefix + "/" + it.key(), out);
  }
}

RunMetrics run_metrics(const Json& summary) {
  RunMetrics m;
  if (summary.contains("robots"))
    for (const auto& r : summary["robots"]) {
      Json copy = r;
      const int id = copy.value("robot", 0);
      copy.erase("robot");
      flatten(copy, "r" + std::to_string(id), m);
    }
  if (summary.contains("metrics")) flatten(summary["metrics"], "", m);
  return m;
}

// One CSV field per RFC 4180: quoted when it holds a comma, quote or line break, inner quotes
// doubled (parameters such as occlusion={"fraction":0.5} hold all of them).
std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string o = "\"";
  for (char c : v) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string csv_row(std::initializer_list<std::string> fields) {
  std::string o;
  for (const auto& f : fields) o += (o.empty() ? "" : ",") + csv_field(f);
  return o + "\n";
}

std::string fmt(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

}  // namespace

Interval mean_ci95(const std::vector<double>& v) {
  Interval iv;
  iv.n = v.size();
  if (v.empty()) return iv;
  double s = 0;
  for (double x : v) s += x;
  iv.mean = s / v.size();
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (v.size() < 2) {
    iv.low = iv.high = iv.mean;
    iv.kind = kNoInterval;
    return iv;
  }
  if (v.size() < kMinTSeeds) {  // no reliable interval with so few seeds: their range, said as such
    iv.low = *lo;
    iv.high = *hi;
    iv.kind = kRangeInterval;
    return iv;
  }
  double s2 = 0;
  for (double x : v) s2 += (x - iv.mean) * (x - iv.mean);
  const double half = t975(v.size() - 1) * std::sqrt(s2 / (v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
  iv.low = iv.mean - half;
  if (*lo >= 0) iv.low = std::max(iv.low, 0.0);  // a non-negative quantity never gets a negative bound
  iv.high = iv.mean + half;
  iv.kind = kT95Interval;
  return iv;
}

std::string interval_text(const Interval& iv, int digits) {
  char b[160];
  if (iv.n == 0) return "-";
  if (iv.n == 1) {
    std::snprintf(b, sizeof b, "%.*f (n=1, no interval)", digits, iv.mean);
  } else if (std::string(iv.kind) == kRangeInterval) {
    std::snprintf(b, sizeof b, "%.*f (seeds' range %.*f to %.*f, n=%zu)", digits, iv.mean, digits, iv.low, digits, iv.high, iv.n);
  } else {
    std::snprintf(b, sizeof b, "%.*f [%.*f, %.*f] (n=%zu, %s)", digits, iv.mean, digits, iv.low, digits, iv.high, iv.n, iv.kind);
  }
  return b;
}

bool run_finished(const fs::path& dir, const SweepRun& r) { return fs::exists(dir / "runs" / r.id / "summary.json"); }

namespace {

// One row of the aggregate: the runs of one scenario x localizer x parameters.
struct Group {
  std::string scenario, localizer, params;
  std::size_t finished = 0, failed = 0, missing = 0;
  std::map<std::string, std::vector<double>> values;
  std::map<std::string, std::size_t> no_value;  // runs whose value of the metric was null (no estimate)
  std::string recall_key;          // the runs' headline recall threshold (summary.json scoring.headline)
  Json external;  // an external client's provenance (summary.json "external"), one entry per distinct client
  std::vector<std::string> names;  // the names an external client's runs recorded (summary.json "localizer"), distinct
  std::set<std::string> given;     // the runs' start_pose_given: "true", "false", "" (a run from before the key)
};

// The name a finished run carries (docs/protocol.md "Which name"): an external client's run records
// it (its label, else ready.name), which the sweep cannot know before the client said ready; a
// built-in localizer's row keeps the sweep's label (two labelled entries of one type stay apart).
std::string run_name(const SweepRun& r, const Json& summary) {
  if (summary.value("localizer_type", std::string()) == "external" && summary.contains("localizer") && summary["localizer"].is_string())
    return summary["localizer"].get<std::string>();
  return r.localizer_label;
}

// summary.json's start_pose_given as a CSV value: "true", "false", or "" where the run predates it.
std::string given_text(const Json& summary) {
  const auto it = summary.find("start_pose_given");
  return it != summary.end() && it->is_boolean() ? (it->get<bool>() ? "true" : "false") : "";
}

// A group's start_pose_given: "true" / "false" when its finished runs agree, "mixed" when not (a
// resume after the client changed its mind; the row then mixes two tasks and says so), "" unknown.
std::string group_given(const Group& g) {
  if (g.given.size() > 1) return "mixed";
  return g.given.empty() ? "" : *g.given.begin();
}

Json given_json(const std::string& v) {
  if (v == "true" || v == "false") return v == "true";
  return v.empty() ? Json(nullptr) : Json(v);
}

// What the folder holds of every run of the sweep, in run order.
struct Census {
  std::vector<Group> groups;
  std::string runs_csv = "index,id,scenario,localizer,params,seed,status,start_pose_given\n";
  std::map<std::string, std::size_t> run_versions;  // which builds made the finished runs (a resume may mix them)
  std::size_t missing = 0, failed = 0;
};

Census take_census(const SweepSpec& spec, const fs::path& dir) {
  Census c;
  std::map<std::string, std::size_t> gindex;
  for (const auto& r : spec.runs) {
    auto [it, inserted] = gindex.try_emplace(r.group(), c.groups.size());
    if (inserted) {
      Group g;
      g.scenario = r.scenario_name;
      g.localizer = r.localizer_label;
      g.params = r.params_label;
      c.groups.push_back(std::move(g));
    }
    Group& g = c.groups[it->second];
    std::string status, name = r.localizer_label, given;
    if (run_finished(dir, r)) {
      status = "ok";
      ++g.finished;
      Json s;
      try {
        s = Json::parse(read_file((dir / "runs" / r.id / "summary.json").string()));
      } catch (const std::exception& e) {
        throw RuntimeFailure("cannot read the finished run " + r.id + ": " + e.what());
      }
      const RunMetrics m = run_metrics(s);
      for (const auto& [k, v] : m.values) g.values[k].push_back(v);
      for (const auto& k : m.nulls) ++g.no_value[k];
      if (g.recall_key.empty() && s.contains("scoring") && s["scoring"].is_object() && s["scoring"].contains("headline") && s["scoring"]["headline"].is_string())
        g.recall_key = s["scoring"]["headline"].get<std::string>();
      name = run_name(r, s);
      given = given_text(s);
      g.given.insert(given);
      const bool external = s.value("localizer_type", std::string()) == "external";
      if (external && std::find(g.names.begin(), g.names.end(), name) == g.names.end()) g.names.push_back(name);
      // Which client made the group's runs (a resume after the client changed may mix several).
      if (s.contains("external")) {
        if (g.external.is_null()) g.external = Json::array();
        if (std::find(g.external.begin(), g.external.end(), s["external"]) == g.external.end()) g.external.push_back(s["external"]);
      }
      ++c.run_versions[s.contains("omniloc") ? s["omniloc"].value("version", std::string("unknown")) : std::string("unrecorded")];
    } else if (fs::exists(dir / "failed" / (r.id + ".json"))) {
      status = "failed";
      ++g.failed;
      ++c.failed;
    } else {
      status = "missing";
      ++g.missing;
      ++c.missing;
    }
    c.runs_csv += csv_row({std::to_string(r.index), r.id, r.scenario_name, name, r.params_label, std::to_string(r.seed), status, given});
  }
  // A row is named as its runs are; several names only when a resume mixed two clients.
  for (Group& g : c.groups) {
    if (g.names.empty()) continue;
    g.localizer.clear();
    for (const auto& n : g.names) g.localizer += (g.localizer.empty() ? "" : "+") + n;
  }
  return c;
}

// A group's name in the printed table. `mark_given`: the table holds rows given the start pose and
// rows that were not; those given it say so.
std::string group_label(const Group& g, bool mark_given) {
  const std::string given = group_given(g);
  const std::string mark = given == "mixed" ? " (start pose: mixed)" : mark_given && given == "true" ? " (given the start pose)" : "";
  return g.scenario + " / " + g.localizer + mark + " / " + g.params;
}

// A group's line of the printed table, its name padded to `width`: robot 0's recall at the headline
// threshold and share of frames answered first (they count every frame, so they lead where
// localizers stand side by side), then its mean errors over the answered frames and its position
// RMSE with interval; "no estimate" where a statistic has no value in any run.
std::string table_line(const Group& g, std::map<std::string, Interval>& ivs, bool phased, bool mark_given, int width) {
  const std::string base = phased ? "r0/tracking_phase/" : "r0/";
  auto cell = [&](const std::string& k, const char* format, double scale) {
    const auto it = ivs.find(base + k);
    if (it == ivs.end() || it->second.n == 0) return std::string(g.no_value.count(base + k) ? "no est." : "-");
    char b[32];
    std::snprintf(b, sizeof b, format, it->second.mean * scale);
    return std::string(b);
  };
  std::string ci = "-";
  if (const auto it = ivs.find("r0/position_m/rmse"); it != ivs.end() && it->second.n > 0) ci = interval_text(it->second, 4);
  else if (g.no_value.count("r0/position_m/rmse")) ci = "no estimate";
  if (const auto nv = g.no_value.find("r0/position_m/rmse"); nv != g.no_value.end() && ci != "no estimate")
    ci += " (no estimate in " + std::to_string(nv->second) + " of " + std::to_string(g.finished) + " runs)";
  const std::string label = group_label(g, mark_given) + (phased ? " *" : "");
  // The limit (summary.json efficiency: the posterior bound when the run has odometry) and the
  // RMSE's multiple of it, over the same frames (the tracking phase's where the runs have one, as
  // the error columns); "-" where no run has one.
  const auto whole = [&](const std::string& k, const char* format, double scale) {
    const std::string key = phased ? "r0/" + k.substr(0, k.find('/')) + "/tracking_phase" + k.substr(k.find('/')) : "r0/" + k;
    const auto it = ivs.find(key);
    if (it == ivs.end() || it->second.n == 0) return std::string("-");
    char b[32];
    std::snprintf(b, sizeof b, format, it->second.mean * scale);
    return std::string(b);
  };
  char line[640];
  std::snprintf(line, sizeof line, " %4zu %4zu | %8s %8s | %9s %9s %9s | %8s %7s | %s\n", g.finished, g.failed,
                g.recall_key.empty() ? "-" : cell("recall/" + g.recall_key, "%.1f%%", 100.0).c_str(), cell("valid_fraction", "%.1f%%", 100.0).c_str(),
                cell("x_cm/mean", "%.3f", 1.0).c_str(), cell("y_cm/mean", "%.3f", 1.0).c_str(), cell("theta_rad/mean", "%.4f", 1.0).c_str(),
                whole("efficiency/bound_rms_m", "%.3f", 100.0).c_str(), whole("efficiency/position", "%.2fx", 1.0).c_str(), ci.c_str());
  return label + std::string(static_cast<std::size_t>(std::max(0, width - static_cast<int>(label.size()))), ' ') + line;
}

// The headline threshold's name for the table's header: the groups', when they agree.
std::string recall_header(const Census& c) {
  std::set<std::string> keys;
  for (const auto& g : c.groups)
    if (!g.recall_key.empty()) keys.insert(g.recall_key);
  return keys.size() == 1 ? *keys.begin() : keys.empty() ? "-" : "(mixed)";
}

// Aggregates every run of the sweep found finished in the folder, in run order: writes runs.csv and
// aggregate.{csv,json} when nothing is missing, and the printed table into `out`.
void write_aggregate_files(const SweepSpec& spec, const fs::path& dir, const Census& census, AggregateOutcome& out) {
  // ci95_low / ci95_high hold what "interval" says (mean_ci95): t95, range (the seeds' min and max)
  // or none (n = 1: the value); "interval" is last so readers of the old columns read them as before.
  // no_value: finished runs in which the metric was null (a statistic over no frame: no estimate);
  // n counts the runs with a value, so n + no_value is every run that reports the metric. A metric
  // without any value has empty mean and interval cells (null in aggregate.json), never 0.
  std::string csv = "scenario,localizer,params,start_pose_given,metric,n,mean,ci95_low,ci95_high,interval,no_value\n";
  // expected / done / failed: a reader sees at once whether every run is in (done counts failed ones).
  Json agg{{"sweep", spec.name}, {"runs", spec.runs.size()}, {"expected", out.expected}, {"done", out.done}, {"failed", out.failed},
           {"complete", out.missing == 0}, {"omniloc", build_info_json()}, {"run_versions", census.run_versions},
           {"groups", Json::array()}};
  bool any_phased = false;
  std::set<std::string> kinds;
  for (const auto& g : census.groups) kinds.insert(group_given(g));
  const bool mark_given = kinds.count("true") && (kinds.count("false") || kinds.count("mixed"));
  int width = 44;  // the names' column: as wide as the longest name (with a phase's " *")
  for (const auto& g : census.groups) width = std::max(width, static_cast<int>(group_label(g, mark_given).size()) + 2);
  char line[640];
  const std::string within = "in " + recall_header(census);
  std::snprintf(line, sizeof line, "%-*s %4s %4s | %8s %8s | %9s %9s %9s | %8s %7s | %-26s\n", width, "scenario / localizer / params", "ok", "fail",
                within.c_str(), "answered", "mean x cm", "mean y cm", "mean th", "limit cm", "x limit", "position RMSE m (t95 for n>=5, else seeds' range)");
  out.table = line;
  for (const auto& g : census.groups) {
    const std::string given = group_given(g);
    Json gj{{"scenario", g.scenario}, {"localizer", g.localizer}, {"params", g.params}, {"start_pose_given", given_json(given)},
            {"finished", g.finished}, {"failed", g.failed}, {"missing", g.missing}, {"metrics", Json::object()}};
    if (!g.external.is_null()) gj["external"] = g.external;
    std::map<std::string, Interval> ivs;
    std::set<std::string> keys;
    for (const auto& kv : g.values) keys.insert(kv.first);
    for (const auto& kv : g.no_value) keys.insert(kv.first);
    for (const auto& k : keys) {
      const auto vit = g.values.find(k);
      Interval iv = vit == g.values.end() ? Interval{} : mean_ci95(vit->second);
      if (is_fraction(k)) iv.high = std::min(iv.high, 1.0);  // a share never has a bound above 1 (nor below 0: mean_ci95)
      const auto nit = g.no_value.find(k);
      const std::size_t none = nit == g.no_value.end() ? 0 : nit->second;
      ivs[k] = iv;
      Json& mj = gj["metrics"][k];
      if (iv.n > 0) {
        mj = {{"n", iv.n}, {"mean", iv.mean}, {"ci95", {iv.low, iv.high}}, {"interval", iv.kind}};
      } else {
        mj = {{"n", 0}, {"mean", nullptr}, {"ci95", nullptr}, {"interval", kNoInterval}};
      }
      mj["no_value"] = none;
      if (none > 0) mj["why"] = "no estimate in " + std::to_string(none) + " of " + std::to_string(none + iv.n) + " runs";
      csv += csv_row({g.scenario, g.localizer, g.params, given, k, std::to_string(iv.n), iv.n ? fmt(iv.mean) : "", iv.n ? fmt(iv.low) : "",
                      iv.n ? fmt(iv.high) : "", iv.kind, std::to_string(none)});
    }
    agg["groups"].push_back(gj);
    // Runs with kidnaps or covers: the tracking phase, as the papers' tables (marked "*").
    const bool phased = ivs.count("r0/tracking_phase/x_cm/mean") > 0;
    out.table += table_line(g, ivs, phased, mark_given, width);
    any_phased = any_phased || phased;
  }
  if (any_phased) out.table += "* runs with kidnaps or covers: errors of the tracking phase (summary.json tracking_phase); RMSE over all frames\n";
  out.table += "limit: the Cramer-Rao bound's position RMS (cm) over the frames with an estimate; x limit: RMSE / limit over them (docs/results.md)\n";
  if (out.missing > 0) {
    // Not final: files a different state of this folder left (a sweep since extended, runs deleted)
    // would pass for this one's result.
    std::error_code ec;
    for (const char* f : {"aggregate.json", "aggregate.csv", "runs.csv"}) fs::remove(dir / f, ec);
    return;
  }
  // aggregate.json last: its presence marks the set complete (tools look for it).
  write_file_atomic((dir / "runs.csv").string(), census.runs_csv);
  write_file_atomic((dir / "aggregate.csv").string(), csv);
  write_file_atomic((dir / "aggregate.json").string(), agg.dump(2) + "\n");
  out.written = true;
}

}  // namespace

std::string run_localizer_name(const fs::path& dir, const SweepRun& r) {
  if (!run_finished(dir, r)) return r.localizer_label;
  try {
    return run_name(r, Json::parse(read_file((dir / "runs" / r.id / "summary.json").string())));
  } catch (const std::exception&) {
    return r.localizer_label;  // only a progress line asks; the aggregate reports an unreadable run
  }
}

AggregateOutcome write_final_aggregate(const SweepSpec& spec, const fs::path& dir) {
  const Census census = take_census(spec, dir);
  AggregateOutcome out;
  out.expected = spec.runs.size();
  out.missing = census.missing;
  out.failed = census.failed;
  out.done = out.expected - out.missing;
  write_aggregate_files(spec, dir, census, out);
  return out;
}

}  // namespace omniloc::batch
