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
#include "experiments/report_format.hpp"
#include "harness/run_directory.hpp"
#include "harness/scenario.hpp"
#include "batch/sweep.hpp"
#include "core/install_paths.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using batch::SweepOptions;
using batch::SweepOutcome;
using batch::SweepSpec;
using batch::load_sweep;
using harness::parse_scenario;
using batch::run_sweep;

namespace fs = std::filesystem;

namespace {

std::string default_file() { return (share_dir() / "scenarios/experiments/error_budget.json").string(); }

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

}  // namespace

// --- configuration --------------------------------------------------------------------------------------

Json ErrorBudgetConfig::scenario_for(const ErrorSource* source, double dur) const {
  Json s = scenario;
  apply(s, baseline, "/baseline");
  if (source) apply(s, source->set, "/sources/" + source->name);
  s["duration"] = dur;
  s["name"] = "budget_" + slug(source ? source->name : std::string("baseline"));
  return s;
}

namespace {

std::vector<ErrorSource> read_sources(JsonReader& r) {
  const Json* src = r.raw("sources", true);
  if (!src->is_array() || src->empty()) throw ConfigError("/sources", json_brief(*src), "a non-empty array of {\"name\", \"set\"}");
  std::vector<ErrorSource> sources;
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
    sources.push_back(std::move(e));
  }
  return sources;
}

}  // namespace

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
  c.sources = read_sources(r);
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

// --- computation ----------------------------------------------------------------------------------------

ErrorBudgetCell ErrorBudgetResult::cell(const std::string& row, const std::string& localizer) const {
  const auto it = cells.find({row, localizer});
  return it == cells.end() ? ErrorBudgetCell{} : it->second;
}

namespace {

/// The rows as scenario files and one sweep over rows x localizers x seeds, staged in `dir`.
struct BudgetSweep {
  SweepSpec spec;
  std::vector<std::string> rows;                         ///< row names, baseline first
  std::map<std::string, std::string> row_of_scenario;    ///< scenario name -> row name
};

BudgetSweep stage_sweep(const ErrorBudgetConfig& c, const ErrorBudgetResult& r, RunDirectory& dir) {
  BudgetSweep b;
  std::vector<std::pair<std::string, const ErrorSource*>> rows{{kBaselineName, nullptr}};
  for (const auto& s : c.sources) rows.emplace_back(s.name, &s);
  Json sweep{{"name", "error_budget"}, {"scenarios", Json::array()}, {"localizers", c.localizers},
             {"seeds", {{"first", r.first_seed}, {"count", r.seeds}}}};
  for (const auto& [name, src] : rows) {
    const Json s = c.scenario_for(src, r.duration);
    const std::string f = "scenarios/" + s["name"].get<std::string>() + ".json";
    dir.write(f, s.dump(2) + "\n");
    sweep["scenarios"].push_back(f);
    b.row_of_scenario[s["name"].get<std::string>()] = name;
    b.rows.push_back(name);
  }
  dir.write("sweep.json", sweep.dump(2) + "\n");
  b.spec = load_sweep(dir.staging() + "/sweep.json");
  return b;
}

/// Per row and localizer: means over the seeds of the finished runs' summaries.
void collect_cells(const BudgetSweep& b, const std::string& sweep_dir, ErrorBudgetResult& r) {
  for (const auto& run : b.spec.runs) {
    if (std::find(r.localizers.begin(), r.localizers.end(), run.localizer_label) == r.localizers.end()) r.localizers.push_back(run.localizer_label);
    ErrorBudgetCell& cell = r.cells[{b.row_of_scenario.at(run.scenario_name), run.localizer_label}];
    const fs::path summary = fs::path(sweep_dir) / "runs" / run.id / "summary.json";
    if (!fs::exists(summary)) {
      ++cell.failed;
      continue;
    }
    const Json sj = read_json_strict(summary.string(), summary.string());
    const Json& rob = sj["robots"][0];
    if (!rob["position_m"]["rmse"].is_number()) {  // null: no estimate in any frame (never averaged as 0)
      ++cell.no_estimate;
      continue;
    }
    cell.per_seed.push_back({run.seed, 100.0 * rob["position_m"]["rmse"].get<double>(), 100.0 * rob["position_m"]["p50"].get<double>(),
                             rob["theta_rmse_rad"].get<double>() * 180.0 / 3.141592653589793, rob.value("wrong_frames", 0L)});
  }
  // The cell's figures from its seeds: means of the errors, the wrong frames summed.
  for (auto& [key, cell] : r.cells)
    if (!cell.per_seed.empty()) {
      std::sort(cell.per_seed.begin(), cell.per_seed.end(), [](const ErrorBudgetSeed& a, const ErrorBudgetSeed& b) { return a.seed < b.seed; });
      cell.runs = static_cast<int>(cell.per_seed.size());
      for (const auto& s : cell.per_seed) {
        cell.rmse_cm += s.rmse_cm;
        cell.p50_cm += s.p50_cm;
        cell.theta_rmse_deg += s.theta_rmse_deg;
        cell.wrong_frames += s.wrong_frames;
      }
      cell.rmse_cm /= cell.runs;
      cell.p50_cm /= cell.runs;
      cell.theta_rmse_deg /= cell.runs;
    }
}

}  // namespace

ErrorBudgetResult compute_error_budget(const ErrorBudgetConfig& c, const std::string& config_file, const ExperimentArgs& args,
                                       RunDirectory& dir, std::ostream& progress) {
  ErrorBudgetResult r;
  r.config_file = config_file;
  r.quick = args.quick;
  r.duration = args.quick ? c.quick_duration : c.duration;
  r.seeds = args.quick ? c.quick_seeds : c.seeds;
  r.first_seed = args.seed;
  const BudgetSweep b = stage_sweep(c, r, dir);
  r.rows = b.rows;
  SweepOptions o;
  o.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::string out_dir = args.out_dir.empty() ? std::string("results/experiments/error_budget") : args.out_dir;
  o.out_dir = fs::path(out_dir).parent_path().parent_path().string() + "/sweeps/error_budget" + (args.quick ? "_quick" : "");
  o.progress = &progress;
  const SweepOutcome so = run_sweep(b.spec, o);
  r.sweep_dir = so.out_dir;
  r.failed_runs = so.failed;
  collect_cells(b, so.out_dir, r);
  return r;
}

// --- report ---------------------------------------------------------------------------------------------

namespace {

std::string budget_markdown(const ErrorBudgetConfig& c, const ErrorBudgetResult& r) {
  std::ostringstream md;
  md << "# error_budget: which error source dominates\n\n";
  if (!c.description.empty()) md << c.description << "\n\n";
  md << "Description file `" << r.config_file << "`; " << strprintf("%.0f s", r.duration) << " of the tracking path, seeds " << r.first_seed
     << ".." << r.first_seed + static_cast<std::uint64_t>(r.seeds) - 1 << (r.quick ? " (quick mode)" : "") << "; machine: " << machine_text()
     << ". Runs: " << r.sweep_dir << ". Means over seeds; position RMSE / median in cm, heading RMSE in degrees.\n\n";
  std::vector<std::string> columns{"source"};
  for (const auto& l : r.localizers) {
    columns.push_back(l + " RMSE cm");
    columns.push_back(l + " p50 cm");
    columns.push_back(l + " heading deg");
  }
  md << md_header(columns);
  for (const auto& name : r.rows) {
    md << "| " << name << " |";
    for (const auto& l : r.localizers) {
      const ErrorBudgetCell cell = r.cell(name, l);
      const std::string none = cell.no_estimate ? strprintf(" (no estimate in %d of %d runs)", cell.no_estimate, cell.no_estimate + cell.runs) : "";
      md << (cell.runs > 0 ? strprintf(" %.2f%s | %.2f | %.2f |", cell.rmse_cm, none.c_str(), cell.p50_cm, cell.theta_rmse_deg)
                           : cell.no_estimate ? " no estimate | | |" : std::string(" failed | | |"));
    }
    md << "\n";
  }
  md << "\nEach row adds one source to the baseline (ideal camera, exact odometry and compass, exact calibration map); "
        "`decentring` includes the model-free calibration, so compare it with `calibration map`. Every magnitude is a "
        "profile's (docs/scenario.md, docs/camera.md), none tuned to the papers.\n";
  return md.str();
}

std::string budget_csv(const ErrorBudgetResult& r) {
  std::ostringstream csv;
  csv << "source,localizer,runs,failed,position_rmse_cm,position_p50_cm,heading_rmse_deg,wrong_frames,no_estimate\n";
  for (const auto& name : r.rows)
    for (const auto& l : r.localizers) {
      const ErrorBudgetCell cell = r.cell(name, l);
      csv << '"' << name << "\"," << l << "," << cell.runs << "," << cell.failed << ","
          << (cell.runs ? strprintf("%.4f,%.4f,%.4f", cell.rmse_cm, cell.p50_cm, cell.theta_rmse_deg) : std::string(",,")) << ","
          << cell.wrong_frames << "," << cell.no_estimate << "\n";
    }
  return csv.str();
}

Json budget_json(const ErrorBudgetResult& r) {
  Json table = Json::array();
  for (const auto& name : r.rows)
    for (const auto& l : r.localizers) {
      const ErrorBudgetCell cell = r.cell(name, l);
      Json row{{"source", name}, {"localizer", l}, {"runs", cell.runs}, {"failed", cell.failed}, {"wrong_frames", cell.wrong_frames},
               {"no_estimate", cell.no_estimate}};
      if (cell.runs > 0) {
        row["position_rmse_cm"] = cell.rmse_cm;
        row["position_p50_cm"] = cell.p50_cm;
        row["heading_rmse_deg"] = cell.theta_rmse_deg;
        Json seeds = Json::array();
        for (const auto& s : cell.per_seed)
          seeds.push_back({{"seed", s.seed}, {"position_rmse_cm", s.rmse_cm}, {"position_p50_cm", s.p50_cm},
                           {"heading_rmse_deg", s.theta_rmse_deg}, {"wrong_frames", s.wrong_frames}});
        row["per_seed"] = seeds;
      }
      table.push_back(row);
    }
  return Json{{"experiment", "error_budget"}, {"config_file", r.config_file}, {"quick", r.quick}, {"duration_s", r.duration},
              {"seeds", r.seeds}, {"first_seed", r.first_seed}, {"sweep", r.sweep_dir}, {"rows", table}};
}

}  // namespace

void write_error_budget_report(const ErrorBudgetConfig& c, const ErrorBudgetResult& r, RunDirectory& dir, std::ostream& out) {
  const std::string md = budget_markdown(c, r);
  dir.write("error_budget.json", budget_json(r).dump(2) + "\n");  // named after the experiment: omniloc report finds it so
  dir.write("budget.csv", budget_csv(r));
  dir.write("README.md", md);
  dir.commit();
  out << md;
}

// --- the experiment -------------------------------------------------------------------------------------

int run_error_budget(const ExperimentArgs& args, std::ostream& out) {
  const std::string file = args.config.empty() ? default_file() : args.config;
  const ErrorBudgetConfig c = load_error_budget(file);
  RunDirectory dir(args.out_dir.empty() ? std::string("results/experiments/error_budget") : args.out_dir);
  const ErrorBudgetResult r = compute_error_budget(c, file, args, dir, out);
  write_error_budget_report(c, r, dir, out);
  return r.failed_runs > 0 ? 1 : 0;
}

}  // namespace omniloc::experiments
