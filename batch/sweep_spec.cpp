#include "batch/sweep_spec.hpp"

#include <filesystem>
#include <map>
#include <optional>
#include <regex>
#include <set>

#include "core/json_parse.hpp"
#include "external/external_config.hpp"
#include "harness/scenario.hpp"
#include "harness/scenario_schema.hpp"
#include "external/sha256.hpp"
#include "harness/localizer_registry.hpp"
#include "harness/recording/replay_scenario.hpp"

namespace omniloc::batch {

namespace fs = std::filesystem;
using harness::parse_scenario;

namespace {

// Largest number of scenario combinations a sweep may hold: every one is validated before any run.
constexpr std::size_t kMaxCombinations = 10000;
// Largest number of runs (combinations x seeds): the run list is held in memory with each run's scenario.
constexpr std::size_t kMaxRuns = 1000000;

std::string sanitize(const std::string& s) {
  std::string o;
  for (char c : s) o += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '=' || c == '+') ? c : '_';
  return o.empty() ? "_" : o;
}

Json read_json_file(const std::string& path, const std::string& what_path) { return read_json_strict(path, what_path); }

// A run's id names its files and folders (runs/<id>/, and ".<id>.partial-HOST-PID.old" beside it
// while it is written, which must stay under NAME_MAX): past 150 characters (long parameter values)
// its tail is replaced by a hash of the whole id, so long ids stay distinct and every name writable.
std::string bounded_id(const std::string& id) {
  if (id.size() <= 150) return id;
  return id.substr(0, 132) + "_h" + external::sha256_hex(id).substr(0, 16);
}


}  // namespace

namespace {

using Combo = std::vector<std::pair<std::string, Json>>;       // JSON pointer -> value
// One entry of a "localizers" list: its row label and the localizer with where it stands in the
// sweep file (or on the command line), so an error in its keys names that path; none: the scenario's own.
struct LocalizerEntry {
  std::string label;
  std::optional<harness::LocalizerSpec> given;
};
using Localizers = std::vector<LocalizerEntry>;

// One entry of "scenarios": the scenario file read, with the localizers and parameter combinations it runs with.
struct ScenarioEntry {
  std::string name;
  Json json;
  Localizers locs;
  std::vector<Combo> combos;
  std::string recording;                   ///< a {"recording": DIR} entry: the folder, absolute
  std::optional<harness::RecordingHeader> header;
};

// The row name of localizer entry `lj` at JSON path `at`: its "label" (checked here, before anything
// reads it as a string), else an external client's script stem (docs/protocol.md), else the type.
// It names the run folders; an external client's rows are named by what its runs record
// (aggregate.cpp run_name: the label, else the client's ready.name).
std::string row_label(const Json& lj, const std::string& at) {
  if (const auto it = lj.find("label"); it != lj.end()) {
    static const std::regex re("[A-Za-z0-9_.-]{1,64}");
    if (!it->is_string() || !std::regex_match(it->get<std::string>(), re))
      throw ConfigError(json_child(at, "label"), json_brief(*it), "a row name: 1-64 characters of [A-Za-z0-9_.-]");
    return it->get<std::string>();
  }
  const auto type = lj.find("type");
  if (type == lj.end()) return "odometry_only";
  if (*type == "external") return external::default_label(lj);
  return type->is_string() ? type->get<std::string>() : std::string("?");
}

// "localizers": [{"type": ...}, ...] at `at`.
Localizers parse_localizers(const Json& l, const std::string& at) {
  if (!l.is_array() || l.empty()) throw ConfigError(at, json_brief(l), "a non-empty array of {\"type\": ...} objects");
  Localizers locs;
  for (std::size_t i = 0; i < l.size(); ++i) {
    Json lj = l[i];
    if (!lj.is_object() || !lj.contains("type")) throw ConfigError(json_child(at, i), json_brief(lj), "an object {\"type\": ...}");
    const std::string lp = json_child(at, i);
    if (!lj["type"].is_string()) throw ConfigError(json_child(lp, "type"), json_brief(lj["type"]), "a localizer type name (omniloc list)");
    std::string label = row_label(lj, lp);
    // It names the sweep's row; a built-in localizer's reader never sees it. An external client's run
    // keeps it: the name its results carry is the label the user gave (docs/protocol.md "Which name").
    if (lj["type"] != "external") lj.erase("label");
    external::anchor_external_paths(lj);
    locs.push_back({sanitize(label), harness::LocalizerSpec(std::move(lj), lp)});
  }
  return locs;
}

// "parameters": {pointer: [values]} at `at`: the cross product of all of them, appended to `base_combos`.
std::vector<Combo> parse_combos(const Json& pj, const std::string& at, const std::vector<Combo>& base_combos) {
  if (!pj.is_object()) throw ConfigError(at, json_brief(pj), "an object {\"/json/pointer\": [values, ...]}");
  std::vector<Combo> combos = base_combos;
  for (auto it = pj.begin(); it != pj.end(); ++it) {
    const std::string pp = json_child(at, it.key());
    if (it.key().empty() || it.key()[0] != '/') throw ConfigError(pp, "\"" + it.key() + "\"", "a JSON pointer such as /robots/0/motion/speed");
    if (!it.value().is_array() || it.value().empty()) throw ConfigError(pp, json_brief(it.value()), "a non-empty array of values");
    // The cross product grows multiplicatively; refuse it before building it (each combination
    // is validated as a scenario below, about 10 ms apiece).
    if (combos.size() * it.value().size() > kMaxCombinations)
      throw ConfigError(pp, "an array of " + std::to_string(it.value().size()) + " values, making " +
                                std::to_string(combos.size() * it.value().size()) + " combinations",
                        "at most " + std::to_string(kMaxCombinations) + " parameter combinations per scenario entry");
    std::vector<Combo> next;
    for (const auto& c : combos)
      for (const auto& v : it.value()) {
        auto c2 = c;
        c2.emplace_back(it.key(), v);
        next.push_back(c2);
      }
    combos = next;
  }
  return combos;
}

// Entry `sp` of "scenarios" written {"recording": DIR, "localizers": ...}: a stored recording (omniloc
// record, docs/recording.md) replayed into each localizer at the recording's seed; no parameters (the
// world is fixed) and no seeds of its own.
ScenarioEntry read_recording_entry(const Json& entry, const std::string& sp, const fs::path& base, const Localizers& locs) {
  JsonReader er(entry, sp);
  er.allow("comment");
  const std::string rel = er.string("recording", std::nullopt);
  ScenarioEntry sc{"", Json(), locs, {{}}, "", std::nullopt};
  if (const Json* l = er.raw("localizers")) sc.locs = parse_localizers(*l, json_child(sp, "localizers"));
  er.finish();
  fs::path p = rel;
  if (p.is_relative()) p = base / p;
  std::error_code ec;
  sc.recording = fs::absolute(p, ec).lexically_normal().string();
  if (ec) throw ConfigError(json_child(sp, "recording"), path_value(p.string(), ec.message()), "a recording folder (relative to the sweep file)");
  try {
    sc.header = harness::RecordingHeader::read(sc.recording);
  } catch (const ConfigError& e) {
    throw ConfigError(json_child(sp, "recording") + " (" + e.path() + ")", e.value(), e.expected());
  }
  sc.name = sc.header->name;
  return sc;
}

// Entry `sp` of "scenarios": a path, or {"file": ..., "parameters": ..., "localizers": ...}.
ScenarioEntry read_scenario_entry(const Json& entry, const std::string& sp, const fs::path& base, const Localizers& locs,
                                  const std::vector<Combo>& combos) {
  ScenarioEntry sc{"", Json(), locs, combos, "", std::nullopt};
  const Json* file = &entry;
  std::string fp = sp;
  if (entry.is_object() && entry.contains("recording")) return read_recording_entry(entry, sp, base, locs);
  if (entry.is_object()) {
    JsonReader er(entry, sp);
    er.allow("comment");
    file = er.raw("file", true);
    fp = json_child(sp, "file");
    if (const Json* l = er.raw("localizers")) sc.locs = parse_localizers(*l, json_child(sp, "localizers"));
    if (const Json* pj = er.raw("parameters")) sc.combos = parse_combos(*pj, json_child(sp, "parameters"), combos);
    er.finish();
  }
  if (!file->is_string())
    throw ConfigError(fp, json_brief(*file), "a scenario file path (relative to the sweep file), or {\"file\": path, \"parameters\": ..., \"localizers\": ...}");
  fs::path p = file->get<std::string>();
  if (p.is_relative()) p = base / p;
  require_readable_file(p.string(), fp, "a readable scenario file (relative to the sweep file)");
  sc.json = read_json_file(p.string(), fp);
  if (!sc.json.is_object()) throw ConfigError(fp, json_brief(*file), "a scenario file holding a JSON object (" + p.string() + " holds " + json_brief(sc.json) + ")");
  sc.name = sc.json.is_object() && sc.json.contains("name") && sc.json["name"].is_string() ? sc.json["name"].get<std::string>() : p.stem().string();
  return sc;
}

std::vector<ScenarioEntry> read_scenario_entries(const Json& scen, const fs::path& base, const Localizers& locs,
                                                 const std::vector<Combo>& combos) {
  if (!scen.is_array() || scen.empty())
    throw ConfigError("/scenarios", json_brief(scen), "a non-empty array of scenario file paths (or {\"file\": ...} / {\"recording\": ...} entries)");
  std::vector<ScenarioEntry> scenarios;
  for (std::size_t i = 0; i < scen.size(); ++i)
    scenarios.push_back(read_scenario_entry(scen[i], json_child("/scenarios", i), base, locs, combos));
  return scenarios;
}

// "seeds": absent (seed 1), a list, or {"first": ..., "count": ...}.
std::vector<std::uint64_t> read_seeds(const Json* sj) {
  std::vector<std::uint64_t> seeds;
  if (!sj) {
    seeds = {1};
  } else if (sj->is_array()) {
    for (std::size_t i = 0; i < sj->size(); ++i) {
      if (!(*sj)[i].is_number_unsigned() || (*sj)[i].get<std::uint64_t>() > (1ULL << 53))
        throw ConfigError(json_child("/seeds", i), json_brief((*sj)[i]), "an integer seed in [0, 2^53] (what a scenario's seed accepts)");
      seeds.push_back((*sj)[i].get<std::uint64_t>());
    }
  } else {
    JsonReader s(*sj, "/seeds");
    const auto first = s.integer("first", 1, 0, 1LL << 52);
    const auto count = s.integer("count", std::nullopt, 1, 100000);
    s.finish();
    for (long long k = 0; k < count; ++k) seeds.push_back(static_cast<std::uint64_t>(first + k));
  }
  if (seeds.empty()) throw ConfigError("/seeds", "[]", "at least one seed");
  if (seeds.size() > 1000000) throw ConfigError("/seeds", std::to_string(seeds.size()) + " seeds", "at most 1000000 seeds");
  return seeds;
}

void check_sweep_size(const std::vector<ScenarioEntry>& scenarios, std::size_t seed_count) {
  std::size_t total = 0;
  for (const auto& sc : scenarios) total += sc.locs.size() * sc.combos.size();
  if (total > kMaxCombinations)
    throw ConfigError("/scenarios", std::to_string(total) + " scenario x localizer x parameter combinations",
                      "at most " + std::to_string(kMaxCombinations) + " (split the sweep)");
  if (total * seed_count > kMaxRuns)
    throw ConfigError("/seeds", std::to_string(total * seed_count) + " runs (" + std::to_string(total) + " combinations x " +
                                    std::to_string(seed_count) + " seeds)",
                      "at most " + std::to_string(kMaxRuns) + " runs in one sweep (split it)");
}

// The scenario with the combination's values written in; `label` gets "leaf=value,..." of them.
Json apply_combo(const Json& scenario, const Combo& combo, std::string& label) {
  Json patched = scenario;
  for (const auto& [ptr, v] : combo) {
    try {
      patched[Json::json_pointer(ptr)] = v;
    } catch (const std::exception& e) {
      throw ConfigError("/parameters" + ptr, json_brief(v), std::string("a pointer into the scenario (") + e.what() + ")");
    }
    const std::size_t cut = ptr.find_last_of('/');
    const std::string leaf = ptr.substr(cut + 1);
    // "enabled=true" does not say what is enabled: a switch is named by what it switches.
    std::string part = leaf + "=" + v.dump();
    if (leaf == "enabled" && v.is_boolean() && cut != std::string::npos && cut > 0)
      part = ptr.substr(ptr.find_last_of('/', cut - 1) + 1, cut - ptr.find_last_of('/', cut - 1) - 1) + (v.get<bool>() ? "=on" : "=off");
    label += (label.empty() ? "" : ",") + part;
  }
  return patched;
}

// A sweep's own localizer entry (`given`) is named by its path in the sweep file, with the run it was
// found in after it; any other error after the run it was found in.
[[noreturn]] void rethrow_in(const ConfigError& e, bool given, const std::string& context) {
  if (given && dynamic_cast<const harness::LocalizerError*>(&e)) throw ConfigError(e.path() + " (" + context + ")", e.value(), e.expected());
  throw ConfigError(context + ": " + (e.path().empty() ? "/" : e.path()), e.value(), e.expected());
}

// The run of a {"recording": DIR} entry with one localizer (none given: the recording's own),
// validated as the replay will read it.
void add_recording_run(const std::string& path, const ScenarioEntry& sc, const LocalizerEntry& le, std::set<std::string>& ids, SweepSpec& spec) {
  const harness::RecordingHeader& h = *sc.header;
  harness::LocalizerSpec loc;
  if (le.given) {
    loc = *le.given;
  } else {
    if (!h.scenario.is_object() || !h.scenario.contains("localizer"))
      throw ConfigError("/localizers", "nothing", "a localizer for the recording " + sc.recording + " (it has none of its own)");
    loc = harness::LocalizerSpec(h.scenario["localizer"], h.dir + "/recording.json /scenario/localizer");
    external::anchor_external_paths(loc.json);
  }
  const std::string label = le.given ? le.label : sanitize(row_label(loc.json, loc.path));
  harness::Scenario parsed;
  try {
    parsed = harness::replay_scenario(h, loc);
  } catch (const ConfigError& e) {
    rethrow_in(e, le.given.has_value(), "sweep " + path + ", recording " + sc.recording + ", localizer \"" + label + "\"");
  }
  SweepRun run;
  run.index = spec.runs.size();
  run.scenario_name = sc.name;
  run.localizer_label = label;
  run.params_label = "recording";
  run.seed = h.seed;
  run.scenario = parsed.input;
  run.recording = sc.recording;
  run.id = bounded_id(sanitize(sc.name) + "__" + label + "__recording__s" + std::to_string(h.seed));
  if (!ids.insert(run.id).second) throw ConfigError("/", run.id, "distinct runs (two entries give the same run id; add \"label\"s)");
  spec.runs.push_back(std::move(run));
}

// Runs that differ only in a built-in localizer that needs vision share their world: it is drawn
// once and replayed into each (docs/recording.md, "Sweeps"). External clients and localizers without
// vision run live (a client may want images; a localizer without a camera must see the world no
// exposure search paused, as its live run does).
void share_worlds(SweepSpec& spec) {
  std::map<std::string, std::vector<SweepRun*>> by_world;
  for (auto& r : spec.runs) {
    if (!r.recording.empty() || !r.scenario.is_object()) continue;
    const Json loc = r.scenario.value("localizer", Json::object());
    const std::string type = loc.is_object() ? loc.value("type", std::string("odometry_only")) : std::string();
    const harness::LocalizerInfo& info = harness::localizer_info(type, "/localizer/type");
    if (type == "external" || !info.needs_vision) continue;
    Json world = r.scenario;
    world.erase("localizer");
    const std::string key = sanitize(r.scenario_name) + "__s" + std::to_string(r.seed) + "__" + external::sha256_hex(world.dump()).substr(0, 16);
    by_world[key].push_back(&r);
  }
  for (auto& [key, runs] : by_world)
    if (runs.size() >= 2)
      for (SweepRun* r : runs) r->world = key;
}

// Validates every combination once, before any run, then adds one run per seed.
void add_runs(const std::string& path, const std::vector<ScenarioEntry>& scenarios, const std::vector<std::uint64_t>& seeds,
              SweepSpec& spec) {
  std::set<std::string> ids;
  for (const auto& sc : scenarios)
    for (const auto& le : sc.locs)
      for (const auto& combo : sc.combos) {
        if (sc.header) {
          add_recording_run(path, sc, le, ids, spec);
          continue;
        }
        std::string plabel;
        Json patched = apply_combo(sc.json, combo, plabel);
        std::string loc_label = le.label;
        harness::Scenario parsed;
        try {
          // The scenario's own localizer names the row; its label is checked before it is read.
          if (!le.given) {
            const Json own = patched.is_object() ? patched.value("localizer", Json::object()) : Json::object();
            loc_label = sanitize(own.is_object() ? row_label(own, "/localizer") : std::string("?"));
          }
          parsed = parse_scenario(patched, sc.name, "", le.given ? &*le.given : nullptr);
        } catch (const ConfigError& e) {
          rethrow_in(e, le.given.has_value(),
                     "sweep " + path + ", scenario \"" + sc.name + "\", localizer \"" + loc_label + "\"" + (plabel.empty() ? "" : ", " + plabel));
        }
        // The runs read the localizer as parsed: the given one in place of the scenario's, external paths absolute.
        if (le.given || patched.contains("localizer")) patched["localizer"] = parsed.localizer.json;
        for (std::uint64_t seed : seeds) {
          SweepRun run;
          run.index = spec.runs.size();
          run.scenario_name = sc.name;
          run.localizer_label = loc_label;
          run.params_label = plabel.empty() ? "default" : plabel;
          run.seed = seed;
          run.scenario = patched;
          run.scenario["seed"] = seed;
          run.scenario["name"] = sc.name;
          run.id = bounded_id(sanitize(sc.name) + "__" + loc_label + "__" + sanitize(run.params_label) + "__s" + std::to_string(seed));
          if (!ids.insert(run.id).second) throw ConfigError("/", run.id, "distinct runs (two combinations give the same run id; add \"label\"s)");
          spec.runs.push_back(std::move(run));
        }
      }
}

}  // namespace

SweepSpec load_sweep(const std::string& path, const Json& localizers) {
  SweepSpec spec;
  spec.source = path;
  const Json j = read_json_file(path, "sweep file");
  JsonReader r(j, "");
  r.allow("comment");
  // The name is a folder (results/sweeps/<name>): as bounded as a scenario's name, and never "." or
  // "..", which would write the sweep's runs/ and specs/ into results/sweeps or results/ itself.
  const bool named = j.is_object() && j.contains("name");
  spec.name = sanitize(r.string("name", fs::path(path).stem().string()));
  if (named && (spec.name.size() > 100 || spec.name == "." || spec.name == ".."))
    throw ConfigError("/name", json_brief(j["name"]), "a sweep name of 1-100 characters, not \".\" or \"..\" (it names results/sweeps/<name>)");
  if (spec.name.size() > 100) spec.name.resize(100);
  if (spec.name == "." || spec.name == "..") spec.name = "sweep";

  // Sweep-wide localizers and parameters apply to every scenario entry; an entry written as
  // {"file": ..., "parameters": {...}, "localizers": [...]} adds its own parameters to the sweep's and
  // replaces the sweep's localizers, so one file can hold rows that vary different things (the paper suite).
  Localizers locs = {{"", std::nullopt}};
  if (const Json* l = r.raw("localizers")) locs = parse_localizers(*l, "/localizers");
  std::vector<Combo> combos = {{}};
  if (const Json* pj = r.raw("parameters")) combos = parse_combos(*pj, "/parameters", combos);
  std::vector<ScenarioEntry> scenarios = read_scenario_entries(*r.raw("scenarios", true), fs::path(path).parent_path(), locs, combos);
  // `omniloc sweep --localizer`: the given localizers replace the file's and its entries' own, so one
  // shipped suite (scenarios/sweeps/ci_quick.json) runs any team's localizer unedited (docs/ci.md).
  if (!localizers.is_null()) {
    const Localizers given = parse_localizers(localizers, "--localizer");
    for (auto& sc : scenarios) sc.locs = given;
  }
  const std::vector<std::uint64_t> seeds = read_seeds(r.raw("seeds"));
  r.finish();

  check_sweep_size(scenarios, seeds.size());
  add_runs(path, scenarios, seeds, spec);
  share_worlds(spec);
  return spec;
}

Json sweep_schema() {
  const Json localizer = harness::scenario_schema()["properties"]["localizer"];
  Json entry = localizer;  // a sweep's localizer entry: a scenario's localizer with a row name
  entry["required"] = Json::array({"type"});
  const Json label = {{"type", "string"}, {"pattern", "^[A-Za-z0-9_.-]{1,64}$"},
                      {"description", "the sweep's row name (default: the type; an external client's rows: its ready.name, its run folders: the script's name)"}};
  const Json localizers = {{"type", "array"}, {"minItems", 1}, {"items", {{"allOf", Json::array({entry, {{"properties", {{"label", label}}}}})}}},
                           {"description", "localizers each scenario runs with (default: the scenario's own)"}};
  const Json parameters = {{"type", "object"},
                           {"propertyNames", {{"pattern", "^/"}}},
                           {"additionalProperties", {{"type", "array"}, {"minItems", 1}}},
                           {"description", "JSON pointer into the scenario -> the values to sweep (cross product)"}};
  const Json file = {{"type", "string"}, {"minLength", 1}, {"description", "a scenario file, relative to the sweep file"}};
  const Json recording = {{"type", "string"}, {"minLength", 1}, {"description", "a recording folder (omniloc record, docs/recording.md), relative to the sweep file"}};
  const Json scenario_entry = {
      {"oneOf", Json::array({file,
                             {{"type", "object"},
                              {"required", {"file"}},
                              {"additionalProperties", false},
                              {"properties", {{"file", file}, {"comment", {{"type", "string"}}}, {"parameters", parameters}, {"localizers", localizers}}}},
                             {{"type", "object"},
                              {"required", {"recording"}},
                              {"additionalProperties", false},
                              {"properties", {{"recording", recording}, {"comment", {{"type", "string"}}}, {"localizers", localizers}}}}})}};
  const Json seed = {{"type", "integer"}, {"minimum", 0}, {"maximum", 9007199254740992LL}};
  return {{"$schema", "https://json-schema.org/draft/2020-12/schema"},
          {"title", "omniloc sweep file"},
          {"type", "object"},
          {"required", {"scenarios"}},
          {"additionalProperties", false},
          {"properties",
           {{"name", {{"type", "string"}, {"description", "results/sweeps/<name>/ (default: the file's name)"}}},
            {"comment", {{"type", "string"}}},
            {"scenarios", {{"type", "array"}, {"minItems", 1}, {"items", scenario_entry}}},
            {"localizers", localizers},
            {"parameters", parameters},
            {"seeds", {{"oneOf", Json::array({{{"type", "array"}, {"minItems", 1}, {"items", seed}},
                                               {{"type", "object"},
                                                {"required", {"count"}},
                                                {"additionalProperties", false},
                                                {"properties",
                                                 {{"first", {{"type", "integer"}, {"minimum", 0}, {"maximum", 4503599627370496LL}}},
                                                  {"count", {{"type", "integer"}, {"minimum", 1}, {"maximum", 100000}}}}}}})}}}}}};
}

}  // namespace omniloc::batch
