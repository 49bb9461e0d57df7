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
#include "experiments/field_picture.hpp"
#include "experiments/plot.hpp"
#include "harness/run_directory.hpp"

namespace omniloc::experiments {

using harness::RunDirectory;

namespace {

constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();

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
    for (std::size_t i = 0; i < v.size(); ++i) capped[i] = std::isfinite(v[i]) ? std::min(v[i], cap_cm) : kNoValue;
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

using Published = Published004;

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
    return pub.found ? 0.5 * (pub.rows[2][i] + pub.rows[4][i]) / ((pub.rows[0][i] + pub.rows[1][i] + pub.rows[3][i]) / 3) : kNoValue;
  };
  return strprintf("edge/centre mean-error ratio: two-circle %.2f, three-point %.2f (published: two-circle %.2f, three-point %.2f); "
                   "max |two-circle - three-point| mean error over the rows %.2e cm",
                   edge_centre_ratio(t, kTwoCircle), edge_centre_ratio(t, kThreePoint), published_ratio(4), published_ratio(7), d);
}

// --- (b') paper 004 as printed ---------------------------------------------------------------------------

const char* const kPostNames[4] = {"yellow (0, 150)", "yellow (0, 250)", "blue (600, 150)", "blue (600, 250)"};

Json post_list(const Field004& f, const std::array<int, 3>& sel) {
  const auto posts = f.posts();
  Json a = Json::array();
  for (int i : sel) a.push_back({100 * posts[static_cast<std::size_t>(i)].x(), 100 * posts[static_cast<std::size_t>(i)].y()});
  return a;
}

Json implied_json(const ImpliedBearings& ib, const std::array<SinglePostFit, 3>& single, const char* const names[3]) {
  Json sp = Json::object();
  for (std::size_t j = 0; j < 3; ++j)
    sp[names[j]] = {{"error_deg", json_number(single[j].error_deg)}, {"miss_cm", json_number(100 * single[j].miss)},
                    {"point_cm", {json_number(100 * single[j].point.x()), json_number(100 * single[j].point.y())}}};
  return {{"diff_deg", {ib.diff_deg[0], ib.diff_deg[1], ib.diff_deg[2]}},
          {"min_bearing_deg", {ib.min_bearing_deg[0], ib.min_bearing_deg[1], ib.min_bearing_deg[2]}},
          {"norm_deg", ib.norm_deg},
          {"single_post", sp}};
}

Json monte_carlo_json(const AsPrintedMonteCarlo& mc) {
  Json rows = Json::array();
  const double n = mc.trials;
  for (std::size_t k = 0; k < 5; ++k)
    rows.push_back({{"true_cm", {kTable1True[k].x(), kTable1True[k].y()}},
                    {"mean_err_two_circle_cm", json_number(mc.mean_err_two_circle_cm[k])},
                    {"mean_err_three_point_cm", json_number(mc.mean_err_three_point_cm[k])},
                    {"n_ge_published_two_circle", mc.n_ge_pub_two_circle[k]},
                    {"p_ge_published_two_circle", static_cast<double>(mc.n_ge_pub_two_circle[k]) / n},
                    {"n_ge_published_three_point", mc.n_ge_pub_three_point[k]},
                    {"p_ge_published_three_point", static_cast<double>(mc.n_ge_pub_three_point[k]) / n},
                    {"chi2_tail_two_circle", mc.chi2_tail_two_circle[k]},
                    {"chi2_tail_three_point", mc.chi2_tail_three_point[k]}});
  return {{"sigma_deg", mc.sigma_deg},
          {"trials_per_position_and_method", mc.trials},
          {"rows", rows},
          {"p_both_edges_ge_published_two_circle", static_cast<double>(mc.n_both_edges_ge_pub) / n},
          {"n_both_edges_ge_published_two_circle", mc.n_both_edges_ge_pub},
          {"p_ratio_ge_published", static_cast<double>(mc.n_ratio_ge_pub) / n},
          {"median_ratio", mc.median_ratio},
          {"p_two_circle_worse_at_all_five", static_cast<double>(mc.n_two_circle_worse_all) / n},
          {"refused", mc.refused},
          {"zero_count_upper95_p", 3.0 / n}};
}

/// /as_printed of table1_004.json and its summary lines (printed and in table1_004.md).
Json as_printed_json(const LandmarkMapsResult& r, std::string& text) {
  const AsPrinted004& ap = r.as_printed;
  if (!ap.done) {
    text += "(b') set-up as printed: not computed (no published table)\n";
    return Json{{"computed", false}};
  }
  static const char* const two_names[3] = {"D1_L", "D1_R", "D2_L"};
  static const char* const three_names[3] = {"P1", "P2", "P3"};
  Json rows = Json::array();
  text += "(b') Paper 004 as printed: posts per method's rule, bearing errors the published estimates imply (deg; angle between posts "
          "seen from the estimate minus from the truth)\n";
  text += "posts: 0 yellow (0, 150), 1 yellow (0, 250), 2 blue (600, 150), 3 blue (600, 250) cm; d(i, j): change of the angle between "
          "the rule's i-th and j-th post; |e|: smallest per-bearing errors giving them\n";
  text += "true (cm)  | two-circle D1_L, D1_R, D2_L | three-point 3 nearest | same | two-circle d(1,2) d(2,3) |e| | three-point "
          "d(1,2) d(2,3) |e| | D2_L alone: error deg, miss cm\n";
  for (std::size_t k = 0; k < 5; ++k) {
    const AsPrintedRow& row = ap.rows[k];
    Json tc_names = Json::array(), tp_names = Json::array();
    for (int i : row.choice.two_circle) tc_names.push_back(kPostNames[i]);
    for (int i : row.choice.three_point) tp_names.push_back(kPostNames[i]);
    rows.push_back({{"true_cm", {kTable1True[k].x(), kTable1True[k].y()}},
                    {"post_dist_cm", {row.post_dist_cm[0], row.post_dist_cm[1], row.post_dist_cm[2], row.post_dist_cm[3]}},
                    {"two_circle_posts_cm", post_list(r.field, row.choice.two_circle)},
                    {"two_circle_posts", tc_names},
                    {"three_point_posts_cm", post_list(r.field, row.choice.three_point)},
                    {"three_point_posts", tp_names},
                    {"same_set", row.choice.same_set},
                    {"d1_tie", row.choice.d1_tie},
                    {"third_nearest_tie", row.choice.third_tie},
                    {"implied_two_circle", implied_json(row.implied_two_circle, row.single_two_circle, two_names)},
                    {"implied_three_point", implied_json(row.implied_three_point, row.single_three_point, three_names)},
                    {"far_goal_width_deg", row.far_goal_width_deg},
                    {"tie_alternative",
                     row.choice.d1_tie || row.choice.third_tie
                         ? Json{{"two_circle_posts_cm", post_list(r.field, row.alt_choice.two_circle)},
                                {"three_point_posts_cm", post_list(r.field, row.alt_choice.three_point)},
                                {"same_set", row.alt_choice.same_set},
                                {"two_circle_diff_deg", {row.alt_two_circle.diff_deg[0], row.alt_two_circle.diff_deg[1], row.alt_two_circle.diff_deg[2]}},
                                {"two_circle_norm_deg", row.alt_two_circle.norm_deg},
                                {"three_point_diff_deg",
                                 {row.alt_three_point.diff_deg[0], row.alt_three_point.diff_deg[1], row.alt_three_point.diff_deg[2]}},
                                {"three_point_norm_deg", row.alt_three_point.norm_deg}}
                         : Json(nullptr)}});
    const auto& a = row.implied_two_circle;
    const auto& b = row.implied_three_point;
    std::string tc, tp;
    for (int i : row.choice.two_circle) tc += std::to_string(i);
    for (int i : row.choice.three_point) tp += std::to_string(i);
    text += strprintf("(%3.0f, %3.0f) | %-27s | %-21s | %-4s | %7.2f %7.2f %6.2f | %7.2f %7.2f %6.2f | %7.2f %6.1f%s\n", kTable1True[k].x(),
                      kTable1True[k].y(), tc.c_str(), tp.c_str(), row.choice.same_set ? "yes" : "NO", a.diff_deg[0], a.diff_deg[1], a.norm_deg,
                      b.diff_deg[0], b.diff_deg[1], b.norm_deg, row.single_two_circle[2].error_deg, 100 * row.single_two_circle[2].miss,
                      row.choice.d1_tie || row.choice.third_tie ? "  (tie)" : "");
  }
  text += strprintf("bearing noise from the paper's three-point results: ML %.3f deg, mean-error match %.3f deg (published three-point mean "
                    "%.2f cm)\n",
                    ap.sigma_ml_deg, ap.sigma_mean_match_deg, ap.published_three_point_mean_cm);
  for (const AsPrintedMonteCarlo* mc : {&ap.mc_mean_match, &ap.mc_ml}) {
    text += strprintf("  sigma %.3f deg, %d single measurements per position and method: P(two-circle err >= published) =", mc->sigma_deg,
                      mc->trials);
    for (std::size_t k = 0; k < 5; ++k) text += strprintf(" %.2e", static_cast<double>(mc->n_ge_pub_two_circle[k]) / mc->trials);
    text += strprintf("; both edges at once %.2e; P(ratio >= %.3f) = %.3f (median %.3f); two-circle worse at all five %.4f\n",
                      static_cast<double>(mc->n_both_edges_ge_pub) / mc->trials, ap.published_ratio,
                      static_cast<double>(mc->n_ratio_ge_pub) / mc->trials, mc->median_ratio,
                      static_cast<double>(mc->n_two_circle_worse_all) / mc->trials);
  }
  return {{"computed", true},
          {"rules",
           {{"two_circle", "sec. 2.2: D1 = goal whose mouth is nearest (fewer pixels to the image centre), D1_L/D1_R its posts (L at the larger "
                           "bearing), D2_L = the nearer post of the other goal"},
            {"three_point", "sec. 2.3: initialised as the two-circle method; the three nearest goal edges, nearest first"},
            {"post_index", {kPostNames[0], kPostNames[1], kPostNames[2], kPostNames[3]}}}},
          {"rows", rows},
          {"published_ratio", ap.published_ratio},
          {"published_three_point_mean_cm", ap.published_three_point_mean_cm},
          {"sigma",
           {{"ml_deg", ap.sigma_ml_deg},
            {"ml_method", "maximum likelihood from the five published three-point estimates: sigma^2 = sum |min_bearing|^2 / (2 x 5) "
                          "(i.i.d. Gaussian bearings; each estimate's implied bearing differences chi-square with 2 dof)"},
            {"mean_match_deg", ap.sigma_mean_match_deg},
            {"mean_match_method", "sigma at which our mean three-point error over the five positions equals the published three-point mean "
                                  "(bisection on common random numbers)"}}},
          {"monte_carlo", {{"mean_match", monte_carlo_json(ap.mc_mean_match)}, {"ml", monte_carlo_json(ap.mc_ml)}}}};
}

/// Table 1 per bearing noise (printed and table1_004.md) beside the published numbers; table1_004.json.
void report_table1(const LandmarkMapsConfig& cfg, const LandmarkMapsResult& r, RunDirectory& dir, std::ostream& out) {
  const Published& pub = r.published;
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
    // The trend as numbers too, for the report's scorecard (python/omniloc/paper/claims.py).
    table_json.push_back({{"bearing_sigma_deg", t.sigma_deg}, {"trials", cfg.table_trials}, {"rows", jrows}, {"trend", trend},
                          {"edge_centre_ratio", {{"two_circle", json_number(edge_centre_ratio(t, kTwoCircle))},
                                                 {"three_point", json_number(edge_centre_ratio(t, kThreePoint))}}}});
  }
  std::string ap_text;
  const Json as_printed = as_printed_json(r, ap_text);
  out << "\n" << ap_text;
  md += "\n## Set-up as printed\n\n```\n" + ap_text + "```\n";
  dir.write("table1_004.json", Json{{"seed", cfg.seed},
                                    {"field_cm", {100 * r.field.length, 100 * r.field.width}},
                                    {"goal_width_cm", 100 * r.field.goal_width},
                                    {"posts_cm", posts_cm_json(r.field)},
                                    {"published_source", pub.found ? "results/reference/papers.json#004_table1_cm" : pub.note},
                                    {"tables", table_json},
                                    {"as_printed", as_printed}}
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
              {"voting_p50_m", quantile(s.err_vote, 0.5)},
              {"voting_p95_m", quantile(s.err_vote, 0.95)},
              {"voting_p99_m", quantile(s.err_vote, 0.99)},
              {"voting_frac_over_1m", s.err_vote.empty() ? 0.0 : static_cast<double>(std::count_if(s.err_vote.begin(), s.err_vote.end(), [](double e) {
                                                             return e > 1.0;
                                                           })) / static_cast<double>(s.err_vote.size())},
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

// Paper 003's real run (its table 1: waypoint, then the measured position; mm): the errors its "maximum
// error about 1 m after rejecting wrong fixes" summarises. Published numbers, copied from the paper's table
// (results/reference/papers.json keeps only the 1 m).
constexpr std::array<std::array<double, 4>, 15> kPaper003Table1 = {{{0, 0, 0, 0},
                                                                     {0, 1000, 168, 1230},
                                                                     {0, 2000, 445, 2467},
                                                                     {0, 3000, 207, 3221},
                                                                     {0, 4000, 1175, 4044},
                                                                     {-1000, 4000, 447, 4412},
                                                                     {-1000, 3000, -979, 3612},
                                                                     {-2000, 3000, -2419, 3613},
                                                                     {-2000, 2000, -2499, 2415},
                                                                     {-2000, 1000, -2636, 1474},
                                                                     {-1000, 1000, -1151, 1275},
                                                                     {-1000, 0, -1426, 152},
                                                                     {-1000, -1000, -1482, -1057},
                                                                     {-1000, -2000, -1297, -2293},
                                                                     {0, -2000, 328, -2239}}};

Json paper_real_run_json() {
  Json err = Json::array();
  double worst = 0.0;
  int at = 0;
  for (std::size_t i = 0; i < kPaper003Table1.size(); ++i) {
    const auto& r = kPaper003Table1[i];
    const double e = std::hypot(r[2] - r[0], r[3] - r[1]) / 1000.0;
    err.push_back(e);
    if (e > worst) {
      worst = e;
      at = static_cast<int>(i) + 1;
    }
  }
  return {{"source", "paper 003 table 1 (waypoint mm, measured mm)"}, {"errors_m", err}, {"max_error_m", worst}, {"max_at_waypoint", at}};
}

Json cause_frame_json(const VotingCauseFrame& c) {
  return {{"path", c.path},
          {"frame", c.frame},
          {"err_m", c.err},
          {"accepted", c.accepted},
          {"fixes", c.fixes},
          {"source_frame", c.source_frame},
          {"frames_since_source", c.source_frame >= 0 ? c.frame - c.source_frame : c.frame + 1},
          {"stale_m", c.stale},
          {"source_err_m", c.source_err},
          {"coord_err_m", json_number(c.coord_err)},
          {"meas_err_m", json_number(c.meas_err)},
          {"dilution_m_per_m", json_number(c.dilution)},
          {"radial_err_max_m", json_number(c.radial_err_max)},
          {"radial_pred_m", json_number(c.radial_pred)},
          {"first_order_sum_m", json_number(c.sum_err)},
          {"cluster", c.cluster}};
}

/// /<condition>/voting_cause of sim_003.json (memory conditions' analysis, VotingCause in landmark_maps.cpp).
Json voting_cause_json(const Sim003Condition& c, std::string& text) {
  const auto& f = c.cause;
  if (f.empty()) return nullptr;
  std::vector<double> err, acc_err;
  long over = 0, over_acc = 0, over_kept_fixes = 0, over_kept_none = 0;
  std::vector<double> over_stale, over_source;
  std::size_t worst = 0, worst_acc = f.size();
  for (std::size_t i = 0; i < f.size(); ++i) {
    err.push_back(f[i].err);
    if (f[i].accepted) acc_err.push_back(f[i].err);
    if (f[i].err > f[worst].err) worst = i;
    if (f[i].accepted && (worst_acc == f.size() || f[i].err > f[worst_acc].err)) worst_acc = i;
    if (f[i].err <= 1.0) continue;
    ++over;
    over_stale.push_back(f[i].stale);
    over_source.push_back(f[i].source_err);
    if (f[i].accepted)
      ++over_acc;
    else if (f[i].fixes > 0)
      ++over_kept_fixes;
    else
      ++over_kept_none;
  }
  // Worst frame of each path: does the max come from the fixes or from keeping the position?
  Json per_path = Json::array();
  int paths_over = 0, paths_over_kept = 0;
  for (int p = 0;; ++p) {
    const VotingCauseFrame* w = nullptr;
    for (const auto& x : f)
      if (x.path == p && (!w || x.err > w->err)) w = &x;
    if (!w) break;
    per_path.push_back(cause_frame_json(*w));
    paths_over += w->err > 1.0;
    paths_over_kept += w->err > 1.0 && !w->accepted;
  }
  const VotingCauseFrame& W = f[worst];
  const double n = static_cast<double>(f.size());
  const auto frac_over = [](const std::vector<double>& v, double x) {
    return v.empty() ? 0.0 : static_cast<double>(std::count_if(v.begin(), v.end(), [&](double e) { return e > x; })) / static_cast<double>(v.size());
  };
  text += strprintf("%s voting error: p50 %.3f p95 %.3f p99 %.3f max %.3f m, %.2f %% of frames > 1 m (%ld: %ld accepted, %ld kept with fixes, "
                    "%ld kept without a fix); accepted frames only: max %.3f m\n",
                    c.name.c_str(), quantile(err, 0.5), quantile(err, 0.95), quantile(err, 0.99), W.err, 100.0 * static_cast<double>(over) / n, over,
                    over_acc, over_kept_fixes, over_kept_none, finite_max(acc_err));
  text += strprintf("  paths whose maximum exceeds 1 m: %d of %zu, %d of them at a frame that kept the last position\n", paths_over,
                    per_path.size(), paths_over_kept);
  text += strprintf("  worst frame: path %d frame %d, error %.3f m, %s; source frame %d (%d frames earlier): stale %.3f m, error there %.3f m = "
                    "remembered coordinates %.3f m + measurement %.3f m; dilution %.2f m per 1 m distance error; largest radial error of the "
                    "remembered coordinates %.3f m, first-order fix error from them %.3f m\n",
                    W.path, W.frame, W.err, W.accepted ? "accepted" : "kept", W.source_frame, W.frame - W.source_frame, W.stale, W.source_err, W.coord_err,
                    W.meas_err, W.dilution, W.radial_err_max, W.radial_pred);
  if (worst_acc < f.size()) {
    const VotingCauseFrame& A = f[worst_acc];
    text += strprintf("  worst accepted frame: path %d frame %d, error %.3f m = remembered coordinates %.3f m + measurement %.3f m (vector sum %.3f m); "
                      "dilution %.2f m per 1 m; largest radial error %.3f m, first-order fix error from them %.3f m; %d fixes averaged\n",
                      A.path, A.frame, A.err, A.coord_err, A.meas_err, A.sum_err, A.dilution, A.radial_err_max, A.radial_pred, A.cluster);
  }
  text += strprintf("  every averaged fix (%zu): remembered-coordinates-only error p50 %.3f p99 %.3f max %.3f m; measurement-only p50 %.3f p99 "
                    "%.3f max %.3f m; dilution p50 %.2f p95 %.2f max %.2f (%.1f %% > 1)\n",
                    c.fix_coord_err.size(), quantile(c.fix_coord_err, 0.5), quantile(c.fix_coord_err, 0.99), finite_max(c.fix_coord_err),
                    quantile(c.fix_meas_err, 0.5), quantile(c.fix_meas_err, 0.99), finite_max(c.fix_meas_err), quantile(c.fix_dilution, 0.5),
                    quantile(c.fix_dilution, 0.95), finite_max(c.fix_dilution), 100.0 * frac_over(c.fix_dilution, 1.0));
  return {{"error_distribution",
           {{"frames", f.size()},
            {"p50_m", quantile(err, 0.5)},
            {"p95_m", quantile(err, 0.95)},
            {"p99_m", quantile(err, 0.99)},
            {"max_m", W.err},
            {"frac_over_1m", static_cast<double>(over) / n},
            {"frames_over_1m", over},
            {"over_1m_accepted", over_acc},
            {"over_1m_kept_with_fixes", over_kept_fixes},
            {"over_1m_kept_without_fix", over_kept_none},
            {"accepted_frames_max_m", finite_max(acc_err)},
            {"accepted_frames_frac_over_1m", frac_over(acc_err, 1.0)},
            {"over_1m_median_stale_m", quantile(over_stale, 0.5)},
            {"over_1m_median_source_err_m", quantile(over_source, 0.5)}}},
          {"worst", cause_frame_json(W)},
          {"worst_accepted", worst_acc < f.size() ? cause_frame_json(f[worst_acc]) : Json(nullptr)},
          {"per_path_worst", per_path},
          {"paths_max_over_1m", paths_over},
          {"paths_max_over_1m_at_kept_frame", paths_over_kept},
          {"fixes",
           {{"count", c.fix_coord_err.size()},
            {"coord_only_p50_m", quantile(c.fix_coord_err, 0.5)},
            {"coord_only_p99_m", quantile(c.fix_coord_err, 0.99)},
            {"coord_only_max_m", finite_max(c.fix_coord_err)},
            {"meas_only_p50_m", quantile(c.fix_meas_err, 0.5)},
            {"meas_only_p99_m", quantile(c.fix_meas_err, 0.99)},
            {"meas_only_max_m", finite_max(c.fix_meas_err)},
            {"dilution_p50", quantile(c.fix_dilution, 0.5)},
            {"dilution_p95", quantile(c.fix_dilution, 0.95)},
            {"dilution_max", finite_max(c.fix_dilution)},
            {"dilution_frac_over_1", frac_over(c.fix_dilution, 1.0)}}},
          // The distance-error bound that would keep a single fix within 1 m to first order: 1 m / dilution.
          {"distance_error_for_1m_at_dilution_max_m", json_number(1.0 / finite_max(c.fix_dilution))},
          {"distance_error_for_1m_at_dilution_p95_m", json_number(1.0 / quantile(c.fix_dilution, 0.95))}};
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
                {"waypoints_per_path", cfg.sim_waypoints},
                {"paper_real_run", paper_real_run_json()}};
  std::string cause_text;
  for (const Sim003Condition& c : r.sim) {
    sim_json[c.name + "_path0"] = sim_path0(c, dir);
    Json per_path = Json::array();
    for (const auto& st : c.paths) per_path.push_back(sim_summary(st));
    const Sim003Stats& a = c.all;
    const Json sum = sim_summary(a);
    sim_json[c.name] = {{"all_paths", sum}, {"per_path", per_path}};
    if (!c.cause.empty()) sim_json[c.name]["voting_cause"] = voting_cause_json(c, cause_text);
    out << strprintf("%-22s | %6d | %10.3f %7.3f (%5ld) | %9.3f %6.3f | %7.3f %6.3f | %9d | %6d | %d\n", c.name.c_str(), a.frames,
                     finite_mean(a.fix_errors), finite_max(a.fix_errors), static_cast<long>(sum["fixes_over_1m"].get<long>()), finite_mean(a.err_novote),
                     finite_max(a.err_novote), finite_mean(a.err_vote), finite_max(a.err_vote), a.kept, a.forced, a.new_groups_vote);
  }
  out << cause_text;
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
