// Report of the "landmark_maps" experiment: the tables printed and written, the maps and plots, the
// JSON files. Every number comes from LandmarkMapsResult (landmark_maps.cpp computes it).
#include <algorithm>
#include <array>
#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "experiments/landmark_maps.hpp"
#include "experiments/report_format.hpp"
#include "harness/field_picture.hpp"
#include "harness/plot.hpp"
#include "harness/run_directory.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;
using harness::Series;
using harness::heat_map;
using harness::line_plot;
using harness::png_bytes;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Json posts_cm_json(const Field004& f) {
  Json a = Json::array();
  for (const auto& p : f.posts()) a.push_back({100 * p.x(), 100 * p.y()});
  return a;
}

// --- (a) maps -------------------------------------------------------------------------------------------

/// maps_004.csv: every cell, every solver's mean error and refused fraction.
std::string maps_csv(const SolverMaps& m) {
  const auto& S = landmark_solvers();
  std::string csv = "x_cm,y_cm";
  for (const auto& s : S) csv += std::string(",") + s.name + "_mean_err_cm," + s.name + "_refused_frac";
  csv += "\n";
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(m.cols) + static_cast<std::size_t>(c);
      csv += strprintf("%.1f,%.1f", 100 * (c + 0.5) * m.cell_m, 100 * (r + 0.5) * m.cell_m);
      for (std::size_t s = 0; s < S.size(); ++s)
        csv += std::isfinite(m.mean_cm[s][i]) ? strprintf(",%.4f,%.4f", m.mean_cm[s][i], m.refused[s][i]) : strprintf(",nan,%.4f", m.refused[s][i]);
      csv += "\n";
    }
  return csv;
}

/// The solver table (printed), one capped heat map per solver and maps_004.csv; returns the solvers' JSON.
Json report_maps(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, RunDirectory& dir, std::ostream& out) {
  const auto& S = landmark_solvers();
  const SolverMaps& m = r.maps;
  const double cap_cm = cfg.cap_cm;
  out << strprintf("\n(a) Mean position error maps: %d x %d cells of %.0f cm, %d trials per cell, bearing noise N(0, %.1f deg), random heading\n",
                   m.cols, m.rows, 100 * m.cell_m, m.trials, m.sigma_deg);
  out << "solver                     | field mean cm | median cm | p95 cm | worst cell cm | cells > " << cap_cm
      << " cm | trials refused | max |fix - total_like| cm\n";
  Json maps_json = Json::array();
  for (std::size_t s = 0; s < S.size(); ++s) {
    const auto& v = m.mean_cm[s];
    const double over = static_cast<double>(std::count_if(v.begin(), v.end(), [&](double x) { return !std::isfinite(x) || x > cap_cm; })) /
                        static_cast<double>(v.size());
    double refused = 0;
    for (double x : m.refused[s]) refused += x;
    refused /= static_cast<double>(m.refused[s].size());
    const double fm = finite_mean(v), med = quantile(v, 0.5), p95 = quantile(v, 0.95), worst = finite_max(v);
    out << strprintf("%-26s | %13.2f | %9.2f | %6.2f | %13.1f | %10.2f %% | %12.4f %% | ", S[s].name, fm, med, p95, worst, 100 * over, 100 * refused)
        << (S[s].exact ? strprintf("%.2e", m.max_diff_vs_total_cm[s]) : std::string("(diagnostic)")) << "\n";
    maps_json.push_back({{"solver", S[s].name},
                         {"label", S[s].label},
                         {"field_mean_cm", fm},
                         {"median_cell_cm", med},
                         {"p95_cell_cm", p95},
                         {"worst_cell_cm", worst},
                         {"cells_over_cap_frac", over},
                         {"trials_refused_frac", refused},
                         {"max_diff_vs_total_like_cm", S[s].exact ? Json(m.max_diff_vs_total_cm[s]) : Json(nullptr)},
                         {"trials_diff_over_1mm", S[s].exact ? Json(m.diff_over_1mm[s]) : Json(nullptr)},
                         {"png", std::string("map_") + S[s].name + ".png"}});
    std::vector<double> capped(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) capped[i] = std::isfinite(v[i]) ? std::min(v[i], cap_cm) : kNaN;
    const int cell_px = std::max(1, static_cast<int>(std::lround(600.0 / m.cols)));
    dir.write(std::string("map_") + S[s].name + ".png",
              png_bytes(heat_map(capped, m.cols, m.rows, 0.0, 100 * r.field.length, 0.0, 100 * r.field.width,
                                 strprintf("%s: mean error cm (0.5 deg, capped %.0f)", S[s].name, cap_cm), "x cm (paper 004 frame)", "y cm",
                                 cell_px)));
  }
  out << strprintf("(the four exact solvers compared with total_like on %ld trials; diagnostics: eqs. (8)/(9) of paper 004 with a fixed "
                   "rotation sign)\n",
                   m.compared);
  dir.write("maps_004.csv", maps_csv(m));
  return maps_json;
}

// --- (b) table 1 ----------------------------------------------------------------------------------------

// Published table: results/reference/papers.json, "004_table1_cm" (the one place published numbers live).
struct Published {
  bool found = false;
  std::string note;
  std::vector<std::array<double, 8>> rows;  // true x, y, two-circle x, y, err, three-point x, y, err
};

Published published_table1() {
  Published p;
  std::string error;
  const Json j = read_published(&error);
  if (!error.empty()) {
    p.note = error;
    return p;
  }
  if (!j.contains("004_table1_cm")) {
    p.note = papers_json_file() + " has no \"004_table1_cm\"";
    return p;
  }
  try {
    for (const auto& r : j.at("004_table1_cm").at("rows")) {
      std::array<double, 8> a{};
      for (std::size_t i = 0; i < 8; ++i) a[i] = r.at(i).get<double>();
      p.rows.push_back(a);
    }
    p.found = p.rows.size() == kTable1True.size();
    if (!p.found) p.note = "004_table1_cm does not have 5 rows";
  } catch (const std::exception& e) {
    p.note = std::string("cannot read published numbers: ") + e.what();
  }
  return p;
}

constexpr std::size_t kTwoCircle = 0, kThreePoint = 1, kEq8 = 4, kEq9 = 5;  // columns of landmark_solvers()

/// One row of table 1 in markdown: ours, the published estimate, the literal readings of eqs. (8)/(9).
std::string table1_row(const Table1& t, std::size_t k, const Published& pub) {
  const auto& tc = t.rows[k][kTwoCircle];
  const auto& tp = t.rows[k][kThreePoint];
  std::string line = strprintf("| (%.0f, %.0f) | (%.1f, %.1f) | %.2f | (%.1f, %.1f) | %.2f | ", kTable1True[k].x(), kTable1True[k].y(), tc.mean_x,
                               tc.mean_y, tc.mean_err, tp.mean_x, tp.mean_y, tp.mean_err);
  if (pub.found) {
    const auto& p = pub.rows[k];
    line += strprintf("(%.0f, %.0f) | %.3f | (%.0f, %.0f) | %.3f | ", p[2], p[3], p[4], p[5], p[6], p[7]);
  } else {
    line += "- | - | - | - | ";
  }
  return line + strprintf("%.1f | %.1f |\n", t.rows[k][kEq8].mean_err, t.rows[k][kEq9].mean_err);
}

Json table1_row_json(const Table1& t, std::size_t k, const Published& pub) {
  const auto& S = landmark_solvers();
  Json per = Json::object();
  for (std::size_t s = 0; s < S.size(); ++s) {
    const auto& c = t.rows[k][s];
    per[S[s].name] = {{"mean_x_cm", json_number(c.mean_x)}, {"mean_y_cm", json_number(c.mean_y)}, {"mean_err_cm", json_number(c.mean_err)},
                      {"max_err_cm", json_number(c.max_err)}, {"ok", c.ok},
                      {"refused", c.refused}};
  }
  Json row{{"true_cm", {kTable1True[k].x(), kTable1True[k].y()}}, {"ours", per}};
  if (pub.found)
    row["published"] = {{"two_circle", {pub.rows[k][2], pub.rows[k][3], pub.rows[k][4]}},
                        {"three_point", {pub.rows[k][5], pub.rows[k][6], pub.rows[k][7]}}};
  return row;
}

/// Near the edge ((75, 100) and (410, 83)) against the three central positions: mean error of `column`.
double edge_centre_ratio(const Table1& t, std::size_t column) {
  const auto& rows = t.rows;
  const double edge = 0.5 * (rows[2][column].mean_err + rows[4][column].mean_err);
  const double centre = (rows[0][column].mean_err + rows[1][column].mean_err + rows[3][column].mean_err) / 3.0;
  return edge / centre;
}

std::string table1_trend(const Table1& t, const Published& pub) {
  double d = 0;
  for (const auto& r : t.rows) d = std::max(d, std::fabs(r[kTwoCircle].mean_err - r[kThreePoint].mean_err));
  const auto published_ratio = [&](std::size_t i) {
    return pub.found ? 0.5 * (pub.rows[2][i] + pub.rows[4][i]) / ((pub.rows[0][i] + pub.rows[1][i] + pub.rows[3][i]) / 3) : kNaN;
  };
  return strprintf("edge/centre mean-error ratio: two-circle %.2f, three-point %.2f (published: two-circle %.2f, three-point %.2f); "
                   "max |two-circle - three-point| mean error over the rows %.2e cm",
                   edge_centre_ratio(t, kTwoCircle), edge_centre_ratio(t, kThreePoint), published_ratio(4), published_ratio(7), d);
}

/// Table 1 per bearing noise (printed and table1_004.md) beside the published numbers; table1_004.json.
void report_table1(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, RunDirectory& dir, std::ostream& out) {
  const Published pub = published_table1();
  if (!pub.found) out << "(published numbers unavailable: " << pub.note << ")\n";
  Json table_json = Json::array();
  std::string md = "# Paper 004, table 1, reproduced (omniloc experiment landmark_maps)\n\n";
  md += strprintf("Field %.0f x %.0f cm (paper 004 frame, origin at a line corner), landmarks = the four goal posts; %d trials per position, "
                  "random heading, seed %llu.\n",
                  100 * r.field.length, 100 * r.field.width, cfg.table_trials, static_cast<unsigned long long>(cfg.seed));
  md += "Ours: mean of the estimates (cm) and mean error (cm) under Gaussian bearing noise. Published: paper 004's single real-robot "
        "estimate and its error (from results/reference/papers.json).\n";
  const std::string head = md_header({"true (cm)", "two-circle mean (cm)", "err", "three-point mean (cm)", "err", "published two-circle", "err",
                                      "published three-point", "err", "eq. (8) literal err", "eq. (9) literal err"});
  for (const Table1& t : r.tables) {
    out << strprintf("\n(b) Paper 004 table 1, bearing noise N(0, %.1f deg), %d trials per position (ours: mean estimate, mean error, cm)\n",
                     t.sigma_deg, cfg.table_trials)
        << head;
    md += strprintf("\n## Bearing noise N(0, %.1f deg)\n\n", t.sigma_deg) + head;
    Json jrows = Json::array();
    for (std::size_t k = 0; k < t.rows.size(); ++k) {
      const std::string line = table1_row(t, k, pub);
      out << line;
      md += line;
      jrows.push_back(table1_row_json(t, k, pub));
    }
    const std::string trend = table1_trend(t, pub);
    out << trend << "\n";
    md += "\n" + trend + ".\n";
    // The trend as numbers too, for the report's scorecard (scripts/paper_claims.py).
    table_json.push_back({{"bearing_sigma_deg", t.sigma_deg}, {"trials", cfg.table_trials}, {"rows", jrows}, {"trend", trend},
                          {"edge_centre_ratio", {{"two_circle", json_number(edge_centre_ratio(t, kTwoCircle))},
                                                 {"three_point", json_number(edge_centre_ratio(t, kThreePoint))}}}});
  }
  dir.write("table1_004.json", Json{{"seed", cfg.seed},
                                    {"field_cm", {100 * r.field.length, 100 * r.field.width}},
                                    {"goal_width_cm", 100 * r.field.goal_width},
                                    {"posts_cm", posts_cm_json(r.field)},
                                    {"published_source", pub.found ? "results/reference/papers.json#004_table1_cm" : pub.note},
                                    {"tables", table_json}}
                                   .dump(1) +
                                   "\n");
  dir.write("table1_004.md", md);
}

// --- (c) paper 003's simulation -------------------------------------------------------------------------

Json sim_summary(const Sim003Stats& s) {
  return Json{{"frames", s.frames},
              {"group_fixes", s.fix_errors.size()},
              {"fixes_mean_m", finite_mean(s.fix_errors)},
              {"fixes_max_m", finite_max(s.fix_errors)},
              {"fixes_over_1m", std::count_if(s.fix_errors.begin(), s.fix_errors.end(), [](double e) { return e > 1.0; })},
              {"no_voting_mean_m", finite_mean(s.err_novote)},
              {"no_voting_max_m", finite_max(s.err_novote)},
              {"voting_mean_m", finite_mean(s.err_vote)},
              {"voting_max_m", finite_max(s.err_vote)},
              {"voting_frames_kept_last", s.kept},
              {"voting_forced_accepts", s.forced},
              {"new_groups_voting_run", s.new_groups_vote},
              {"new_groups_no_voting_run", s.new_groups_novote}};
}

/// Path 0 of a condition: its error plot (sim_003_<condition>.png) and its per-frame series as JSON.
Json sim_path0(const Sim003Condition& c, RunDirectory& dir) {
  const Sim003Stats& st = c.paths.front();
  Series sv{"voting", {}, st.err_vote}, sn{"no voting", {}, st.err_novote}, sw{"worst group fix", {}, {}};
  for (std::size_t i = 0; i < st.err_vote.size(); ++i) {
    sv.x.push_back(static_cast<double>(i));
    sn.x.push_back(static_cast<double>(i));
    if (std::isfinite(st.worst_fix[i])) {
      sw.x.push_back(static_cast<double>(i));
      sw.y.push_back(st.worst_fix[i]);
    }
  }
  dir.write("sim_003_" + c.name + ".png", png_bytes(line_plot({sw, sn, sv}, "Paper 003 simulation, " + c.name + ", path 0: position error", "frame", "error m")));
  Json series{{"truth", Json::array()}, {"err_vote_m", st.err_vote}, {"err_novote_m", st.err_novote}, {"worst_fix_m", Json::array()}};
  for (const auto& p : c.path0_truth) series["truth"].push_back({p.x, p.y, p.theta});
  for (double w : st.worst_fix) series["worst_fix_m"].push_back(json_number(w));
  return series;
}

/// The conditions' table (printed), the path-0 plots and sim_003.json.
void report_sim003(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, RunDirectory& dir, std::ostream& out) {
  out << "\n(c) Paper 003 simulation: landmarks (+-4, +-4) m (the paper's (+-40, +-40) read as decimetres), range 8 m, distance error "
         "U(-1, 1) m, bearing noise N(0, 1 deg); "
      << cfg.sim_paths << " random paths of " << cfg.sim_waypoints << " waypoints (path 0 plotted)\n";
  out << "condition              | frames | group fixes: mean m   max m  (>1 m) | no voting: mean m  max m | voting: mean m  max m | kept last | "
         "forced | new groups\n";
  Json sim_json{{"landmarks_m", {{-4, -4, "red"}, {-4, 4, "blue"}, {4, -4, "yellow"}, {4, 4, "red"}}},
                {"range_m", 8.0},
                {"distance_error", "uniform [-1, 1] m"},
                {"bearing_noise_deg", 1.0},
                {"match", {{"max_distance_diff_m", 2.0}, {"max_angle_diff_deg", 45.0}}},
                {"voting", {{"position_tol_m", 0.5}, {"heading_tol_deg", 10.0}, {"deadlock_limit", 3}}},
                {"plausible_margin_m", LandmarkMapsResult::kSimRegionMargin},
                {"paths", cfg.sim_paths},
                {"waypoints_per_path", cfg.sim_waypoints}};
  for (const Sim003Condition& c : r.sim) {
    sim_json[c.name + "_path0"] = sim_path0(c, dir);
    Json per_path = Json::array();
    for (const auto& st : c.paths) per_path.push_back(sim_summary(st));
    const Sim003Stats& a = c.all;
    const Json sum = sim_summary(a);
    sim_json[c.name] = {{"all_paths", sum}, {"per_path", per_path}};
    out << strprintf("%-22s | %6d | %10.3f %7.3f (%5ld) | %9.3f %6.3f | %7.3f %6.3f | %9d | %6d | %d\n", c.name.c_str(), a.frames,
                     finite_mean(a.fix_errors), finite_max(a.fix_errors), static_cast<long>(sum["fixes_over_1m"].get<long>()), finite_mean(a.err_novote),
                     finite_max(a.err_novote), finite_mean(a.err_vote), finite_max(a.err_vote), a.kept, a.forced, a.new_groups_vote);
  }
  dir.write("sim_003.json", sim_json.dump() + "\n");  // per-frame series: compact
}

}  // namespace

void write_landmark_maps_report(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, RunDirectory& dir, std::ostream& out) {
  const Field004& field = r.field;
  const auto posts = field.posts();
  out << "landmark_maps (seed " << cfg.seed << (cfg.quick ? ", quick" : "") << ")\n";
  out << strprintf("Paper 004 field, paper's frame (origin at a line corner, cm): %.0f x %.0f cm; yellow goal posts (%.0f,%.0f) (%.0f,%.0f), "
                   "blue goal posts (%.0f,%.0f) (%.0f,%.0f)\n",
                   100 * field.length, 100 * field.width, 100 * posts[0].x(), 100 * posts[0].y(), 100 * posts[1].x(), 100 * posts[1].y(),
                   100 * posts[2].x(), 100 * posts[2].y(), 100 * posts[3].x(), 100 * posts[3].y());
  const Json maps_json = report_maps(cfg, r, dir, out);
  report_table1(cfg, r, dir, out);
  report_sim003(cfg, r, dir, out);

  const SolverMaps& m = r.maps;
  Json top{{"seed", cfg.seed},
           {"quick", cfg.quick},
           {"field_004", {{"size_cm", {100 * field.length, 100 * field.width}}, {"goal_width_cm", 100 * field.goal_width},
                          {"posts_cm", posts_cm_json(field)}, {"yellow_goal_x_cm", 0.0}, {"blue_goal_x_cm", 100 * field.length}}},
           {"maps", {{"cell_cm", 100 * m.cell_m}, {"cols", m.cols}, {"rows", m.rows}, {"trials_per_cell", m.trials},
                     {"bearing_sigma_deg", m.sigma_deg}, {"cap_cm", cfg.cap_cm}, {"solvers", maps_json}}},
           {"files", {"maps_004.csv", "table1_004.json", "table1_004.md", "sim_003.json", "sim_003_paper_consecutive.png", "sim_003_paper_memory.png",
                      "sim_003_distractor_consecutive.png", "sim_003_distractor_memory.png"}}};
  dir.write("landmark_maps.json", top.dump(1) + "\n");
  dir.commit();
  out << "\nwritten: " << dir.final_dir() << "/{landmark_maps.json, maps_004.csv, map_*.png, table1_004.{json,md}, sim_003.json, sim_003_*.png}\n";
}

}  // namespace omniloc::experiments
