#include "experiments/error_budget.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <sstream>
#include <thread>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/json_parse.hpp"
#include "experiments/text_format.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "harness/sweep.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using harness::SweepOptions;
using harness::SweepOutcome;
using harness::SweepSpec;
using harness::load_sweep;
using harness::parse_scenario;
using harness::run_sweep;

namespace fs = std::filesystem;

namespace {

std::string default_file() { return std::string(OMNILOC_SOURCE_DIR) + "/scenarios/experiments/error_budget.json"; }

std::string slug(const std::string& name) {
  std::string s;
  for (char c : name) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c));
    if (keep) s += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    else if (!s.empty() && s.back() != '_') s += '_';
  }
  while (!s.empty() && s.back() == '_') s.pop_back();
  return s.empty() ? std::string("source") : s;
}

// Applies {"/json/pointer": value, ...} to `j`, creating objects on the way.
void apply(Json& j, const Json& set, const std::string& at) {
  for (auto it = set.begin(); it != set.end(); ++it) {
    try {
      j[Json::json_pointer(it.key())] = it.value();
    } catch (const std::exception& e) {
      throw ConfigError(json_child(at, it.key()), json_brief(it.value()), std::string("a JSON pointer into the scenario (") + e.what() + ")");
    }
  }
}

const char* kBaselineName = "none (baseline)";

struct Cell {
  int n = 0, failed = 0;
  double rmse_cm = 0, p50_cm = 0, theta_rmse_deg = 0;
  long wrong_frames = 0;
};

}  // namespace

Json ErrorBudgetConfig::scenario_for(const ErrorSource* source, double dur) const {
  Json s = scenario;
  apply(s, baseline, "/baseline");
  if (source) apply(s, source->set, "/sources/" + source->name);
  s["duration"] = dur;
  s["name"] = "budget_" + slug(source ? source->name : std::string("baseline"));
  return s;
}

ErrorBudgetConfig load_error_budget(const std::string& file) {
  const Json j = read_json_strict(file, file);
  JsonReader r(j, "");
  r.allow("comment");
  r.allow("experiment");
  ErrorBudgetConfig c;
  c.description = r.string("description", std::string());
  c.scenario_file = (fs::path(file).parent_path() / r.string("scenario", std::nullopt)).lexically_normal().string();
  require_readable_file(c.scenario_file, "/scenario", "a scenario file (relative to the description file)");
  c.scenario = read_json_strict(c.scenario_file, c.scenario_file);
  c.duration = r.positive("duration", 60.0, 3600.0);
  c.seeds = static_cast<int>(r.integer("seeds", 3, 1, 100));
  if (auto q = r.object("quick")) {
    c.quick_duration = q->positive("duration", 20.0, 3600.0);
    c.quick_seeds = static_cast<int>(q->integer("seeds", 1, 1, 100));
    q->finish();
  }
  const Json* locs = r.raw("localizers", true);
  if (!locs->is_array() || locs->empty()) throw ConfigError("/localizers", json_brief(*locs), "a non-empty array of {\"type\": ...}");
  c.localizers = *locs;
  const Json* base = r.raw("baseline");
  c.baseline = base ? *base : Json::object();
  if (!c.baseline.is_object()) throw ConfigError("/baseline", json_brief(c.baseline), "an object {\"/json/pointer\": value}");
  const Json* src = r.raw("sources", true);
  if (!src->is_array() || src->empty()) throw ConfigError("/sources", json_brief(*src), "a non-empty array of {\"name\", \"set\"}");
  std::map<std::string, int> seen;
  for (std::size_t i = 0; i < src->size(); ++i) {
    const std::string at = json_child("/sources", i);
    JsonReader sr((*src)[i], at);
    sr.allow("comment");
    ErrorSource e;
    e.name = sr.string("name", std::nullopt);
    const Json* set = sr.raw("set", true);
    if (!set->is_object()) throw ConfigError(json_child(at, "set"), json_brief(*set), "an object {\"/json/pointer\": value}");
    e.set = *set;
    sr.finish();
    if (seen[slug(e.name)]++) throw ConfigError(json_child(at, "name"), "\"" + e.name + "\"", "a name distinct from the other sources'");
    c.sources.push_back(std::move(e));
  }
  r.finish();
  // Every row must be a valid scenario now, not after an hour of runs.
  parse_scenario(c.scenario_for(nullptr, c.duration), "budget", c.scenario_file);
  for (const auto& s : c.sources) {
    try {
      parse_scenario(c.scenario_for(&s, c.duration), "budget", c.scenario_file);
    } catch (const ConfigError& e) {
      throw ConfigError("/sources/" + s.name + " -> scenario" + e.path(), e.value(), e.expected());
    }
  }
  return c;
}

void validate_error_budget(const std::string& file) { (void)load_error_budget(file); }

int run_error_budget(const ExperimentArgs& args, std::ostream& out) {
  const std::string file = args.config.empty() ? default_file() : args.config;
  const ErrorBudgetConfig c = load_error_budget(file);
  const double duration = args.quick ? c.quick_duration : c.duration;
  const int seeds = args.quick ? c.quick_seeds : c.seeds;
  const std::string out_dir = args.out_dir.empty() ? std::string("results/experiments/error_budget") : args.out_dir;
  RunDirectory dir(out_dir);

  // The rows as scenario files and one sweep over rows x localizers x seeds (child processes, -j cores).
  std::vector<std::pair<std::string, const ErrorSource*>> rows{{kBaselineName, nullptr}};
  for (const auto& s : c.sources) rows.emplace_back(s.name, &s);
  Json sweep{{"name", "error_budget"}, {"scenarios", Json::array()}, {"localizers", c.localizers},
             {"seeds", {{"first", args.seed}, {"count", seeds}}}};
  std::map<std::string, std::string> row_of_scenario;
  for (const auto& [name, src] : rows) {
    const Json s = c.scenario_for(src, duration);
    const std::string f = "scenarios/" + s["name"].get<std::string>() + ".json";
    dir.write(f, s.dump(2) + "\n");
    sweep["scenarios"].push_back(f);
    row_of_scenario[s["name"].get<std::string>()] = name;
  }
  dir.write("sweep.json", sweep.dump(2) + "\n");
  const SweepSpec spec = load_sweep(dir.staging() + "/sweep.json");
  SweepOptions o;
  o.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  o.out_dir = fs::path(out_dir).parent_path().parent_path().string() + "/sweeps/error_budget" + (args.quick ? "_quick" : "");
  o.progress = &out;
  const SweepOutcome so = run_sweep(spec, o);

  // Per row and localizer: means over the seeds.
  std::map<std::pair<std::string, std::string>, Cell> cells;
  std::vector<std::string> locs;
  for (const auto& r : spec.runs) {
    if (std::find(locs.begin(), locs.end(), r.localizer_label) == locs.end()) locs.push_back(r.localizer_label);
    Cell& cell = cells[{row_of_scenario[r.scenario_name], r.localizer_label}];
    const fs::path summary = fs::path(so.out_dir) / "runs" / r.id / "summary.json";
    if (!fs::exists(summary)) {
      ++cell.failed;
      continue;
    }
    const Json sj = read_json_strict(summary.string(), summary.string());
    const Json& rob = sj["robots"][0];
    ++cell.n;
    cell.rmse_cm += 100.0 * rob["position_m"]["rmse"].get<double>();
    cell.p50_cm += 100.0 * rob["position_m"]["p50"].get<double>();
    cell.theta_rmse_deg += rob.value("theta_rmse_rad", 0.0) * 180.0 / 3.141592653589793;
    cell.wrong_frames += rob.value("wrong_frames", 0L);
  }
  Json table = Json::array();
  std::ostringstream md, csv;
  csv << "source,localizer,runs,failed,position_rmse_cm,position_p50_cm,heading_rmse_deg,wrong_frames\n";
  md << "# error_budget: which error source dominates\n\n";
  if (!c.description.empty()) md << c.description << "\n\n";
  md << "Description file `" << file << "`; " << strprintf("%.0f s", duration) << " of the tracking path, seeds " << args.seed << ".."
     << args.seed + static_cast<std::uint64_t>(seeds) - 1 << (args.quick ? " (quick mode)" : "") << "; machine: " << machine_text()
     << ". Runs: " << so.out_dir << ". Means over seeds; position RMSE / median in cm, heading RMSE in degrees.\n\n";
  md << "| source |";
  for (const auto& l : locs) md << " " << l << " RMSE cm | " << l << " p50 cm | " << l << " heading deg |";
  md << "\n|---|";
  for (std::size_t i = 0; i < locs.size(); ++i) md << "---|---|---|";
  md << "\n";
  for (const auto& [name, src] : rows) {
    md << "| " << name << " |";
    for (const auto& l : locs) {
      Cell cell = cells[{name, l}];
      if (cell.n > 0) {
        cell.rmse_cm /= cell.n;
        cell.p50_cm /= cell.n;
        cell.theta_rmse_deg /= cell.n;
        md << strprintf(" %.2f | %.2f | %.2f |", cell.rmse_cm, cell.p50_cm, cell.theta_rmse_deg);
      } else {
        md << " failed | | |";
      }
      Json row{{"source", name}, {"localizer", l}, {"runs", cell.n}, {"failed", cell.failed}, {"wrong_frames", cell.wrong_frames}};
      if (cell.n > 0) {
        row["position_rmse_cm"] = cell.rmse_cm;
        row["position_p50_cm"] = cell.p50_cm;
        row["heading_rmse_deg"] = cell.theta_rmse_deg;
      }
      table.push_back(row);
      csv << '"' << name << "\"," << l << "," << cell.n << "," << cell.failed << ","
          << (cell.n ? strprintf("%.4f,%.4f,%.4f", cell.rmse_cm, cell.p50_cm, cell.theta_rmse_deg) : std::string(",,")) << ","
          << cell.wrong_frames << "\n";
    }
    md << "\n";
  }
  md << "\nEach row adds one source to the baseline (ideal camera, exact odometry and compass, exact calibration map); "
        "`decentring` includes the model-free calibration, so compare it with `calibration map`. Every magnitude is a "
        "profile's (docs/scenario.md, docs/camera.md), none tuned to the papers.\n";
  Json result{{"experiment", "error_budget"}, {"config_file", file}, {"quick", args.quick}, {"duration_s", duration},
              {"seeds", seeds}, {"first_seed", args.seed}, {"sweep", so.out_dir}, {"rows", table}};
  dir.write("error_budget.json", result.dump(2) + "\n");  // named after the experiment: scripts/report.py finds it so
  dir.write("budget.csv", csv.str());
  dir.write("README.md", md.str());
  dir.commit();
  out << md.str();
  return so.failed > 0 ? 1 : 0;
}

}  // namespace omniloc::experiments
