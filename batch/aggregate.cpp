#include "batch/aggregate.hpp"

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/version.hpp"

namespace omniloc::batch {

namespace fs = std::filesystem;

namespace {

// Student t 0.975 quantiles for 1..30 degrees of freedom, then the normal value.
double t975(std::size_t df) {
  static const double t[] = {0,     12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                             2.201, 2.179,  2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080,
                             2.074, 2.069,  2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  return df <= 30 ? t[df] : 1.96;
}

void flatten(const Json& j, const std::string& prefix, std::map<std::string, double>& out) {
  if (j.is_number()) {
    out[prefix] = j.get<double>();
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) flatten(it.value(), prefix.empty() ? it.key() : prefix + "/" + it.key(), out);
  }
}

std::map<std::string, double> run_metrics(const Json& summary) {
  std::map<std::string, double> m;
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
  if (v.size() < 2) {
    iv.low = iv.high = iv.mean;
    return iv;
  }
  double s2 = 0;
  for (double x : v) s2 += (x - iv.mean) * (x - iv.mean);
  const double half = t975(v.size() - 1) * std::sqrt(s2 / (v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
  iv.low = iv.mean - half;
  iv.high = iv.mean + half;
  return iv;
}

bool run_finished(const fs::path& dir, const SweepRun& r) { return fs::exists(dir / "runs" / r.id / "summary.json"); }

namespace {

// One row of the aggregate: the runs of one scenario x localizer x parameters.
struct Group {
  std::string scenario, localizer, params;
  std::size_t finished = 0, failed = 0, missing = 0;
  std::map<std::string, std::vector<double>> values;
  Json external;  // an external client's provenance (summary.json "external"), one entry per distinct client
};

// What the folder holds of every run of the sweep, in run order.
struct Census {
  std::vector<Group> groups;
  std::string runs_csv = "index,id,scenario,localizer,params,seed,status\n";
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
    std::string status;
    if (run_finished(dir, r)) {
      status = "ok";
      ++g.finished;
      Json s;
      try {
        s = Json::parse(read_file((dir / "runs" / r.id / "summary.json").string()));
      } catch (const std::exception& e) {
        throw RuntimeFailure("cannot read the finished run " + r.id + ": " + e.what());
      }
      for (const auto& [k, v] : run_metrics(s)) g.values[k].push_back(v);
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
    c.runs_csv +=
        csv_row({std::to_string(r.index), r.id, r.scenario_name, r.localizer_label, r.params_label, std::to_string(r.seed), status});
  }
  return c;
}

// A group's line of the printed table: robot 0's mean errors, its position RMSE with interval.
std::string table_line(const Group& g, std::map<std::string, Interval>& ivs, bool phased) {
  auto m = [&](const std::string& k) {
    const std::string key = phased ? "r0/tracking_phase/" + k : "r0/" + k;
    return ivs.count(key) ? ivs[key].mean : NAN;
  };
  char ci[64];
  if (ivs.count("r0/position_m/rmse")) {
    const Interval& iv = ivs["r0/position_m/rmse"];
    if (iv.n >= 2) std::snprintf(ci, sizeof ci, "%.4f [%.4f, %.4f] n=%zu", iv.mean, iv.low, iv.high, iv.n);
    else std::snprintf(ci, sizeof ci, "%.4f (n=1, no interval)", iv.mean);  // one seed has no spread
  } else {
    std::snprintf(ci, sizeof ci, "-");
  }
  const std::string label = g.scenario + " / " + g.localizer + " / " + g.params + (phased ? " *" : "");
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %4zu %4zu | %9.3f %9.3f %9.4f | %s\n", label.c_str(), g.finished, g.failed,
                m("x_cm/mean"), m("y_cm/mean"), m("theta_rad/mean"), ci);
  return line;
}

// Aggregates every run of the sweep found finished in the folder, in run order: writes runs.csv and
// aggregate.{csv,json} when nothing is missing, and the printed table into `out`.
void write_aggregate_files(const SweepSpec& spec, const fs::path& dir, const Census& census, AggregateOutcome& out) {
  std::string csv = "scenario,localizer,params,metric,n,mean,ci95_low,ci95_high\n";
  // expected / done / failed: a reader sees at once whether every run is in (done counts failed ones).
  Json agg{{"sweep", spec.name}, {"runs", spec.runs.size()}, {"expected", out.expected}, {"done", out.done}, {"failed", out.failed},
           {"complete", out.missing == 0}, {"omniloc", build_info_json()}, {"run_versions", census.run_versions},
           {"groups", Json::array()}};
  char line[512];
  std::snprintf(line, sizeof line, "%-44s %4s %4s | %9s %9s %9s | %-26s\n", "scenario / localizer / params", "ok", "fail", "mean x cm",
                "mean y cm", "mean th", "position RMSE m (95 % CI)");
  out.table = line;
  bool any_phased = false;
  for (const auto& g : census.groups) {
    Json gj{{"scenario", g.scenario}, {"localizer", g.localizer}, {"params", g.params}, {"finished", g.finished},
            {"failed", g.failed}, {"missing", g.missing}, {"metrics", Json::object()}};
    if (!g.external.is_null()) gj["external"] = g.external;
    std::map<std::string, Interval> ivs;
    for (const auto& [k, v] : g.values) {
      const Interval iv = mean_ci95(v);
      ivs[k] = iv;
      gj["metrics"][k] = {{"n", iv.n}, {"mean", iv.mean}, {"ci95", {iv.low, iv.high}}};
      csv += csv_row({g.scenario, g.localizer, g.params, k, std::to_string(iv.n), fmt(iv.mean), fmt(iv.low), fmt(iv.high)});
    }
    agg["groups"].push_back(gj);
    // Runs with kidnaps or covers: the tracking phase, as the papers' tables (marked "*").
    const bool phased = ivs.count("r0/tracking_phase/x_cm/mean") > 0;
    out.table += table_line(g, ivs, phased);
    any_phased = any_phased || phased;
  }
  if (any_phased) out.table += "* runs with kidnaps or covers: errors of the tracking phase (summary.json tracking_phase); RMSE over all frames\n";
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
