#pragma once
// What the experiments' reports share: statistics over samples, number formatting for text tables,
// markdown table rows and the published figures (results/reference/papers.json). One copy here; an
// experiment's own report code only arranges these.
#include <cstdio>
#include <string>
#include <vector>

#include "core/json_reader.hpp"

namespace omniloc::experiments {

// --- text -----------------------------------------------------------------------------------------

/// `f` with `a...` as std::snprintf would print them, cut at 511 characters.
template <class... A>
std::string strprintf(const char* f, A... a) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, a...);
  return buf;
}

/// "<CPU model>, <n> hardware threads": the machine a table was measured on.
std::string machine_text();

/// `metres` in millimetres with `prec` decimals; "n/a" when not finite (an undefined figure).
std::string mm(double metres, int prec = 1);
/// `rad` in degrees with `prec` decimals; "n/a" when not finite.
std::string deg(double rad, int prec = 2);
/// JSON cannot hold NaN or infinity: undefined figures (an empty bin, a refused fix) become null.
Json json_number(double v);

/// One markdown table row: "| a | b |\n".
std::string md_row(const std::vector<std::string>& cells);
/// A markdown table's header row and rule: "| a | b |\n|---|---|\n".
std::string md_header(const std::vector<std::string>& columns);

// --- statistics -----------------------------------------------------------------------------------

/// Mean of all values; NaN when empty.
double mean(const std::vector<double>& v);
/// Sample standard deviation (two-pass); NaN below two values.
double sd(const std::vector<double>& v);
/// Median (the mean of the two middle values for an even count); NaN when empty.
double median(std::vector<double> v);
/// Nearest-rank quantile q in [0, 1] of the finite values (index round(q (n - 1)); q = 0.5 gives the
/// upper of the two middle values); NaN when there are none.
double quantile(std::vector<double> v, double q);
/// Mean and maximum of the finite values only (NaN marks "no value" in those series); NaN when none.
double finite_mean(const std::vector<double>& v);
double finite_max(const std::vector<double>& v);

/// Running mean and variance (Welford) of values seen one at a time.
struct RunningStat {
  double n = 0, mean = 0, m2 = 0;
  void add(double x);
  double sd() const;  ///< sample standard deviation; 0 below two values
  double se() const;  ///< standard error of the mean; 0 below two values
};

// --- published figures ----------------------------------------------------------------------------

/// results/reference/papers.json in the source tree: the one place the papers' numbers live.
std::string papers_json_file();
/// Its contents; an empty object when it is missing or unreadable (then `error`, if given, says why).
Json read_published(std::string* error = nullptr);
/// papers[group][key] when it is a number; NaN otherwise.
double published_number(const Json& papers, const std::string& group, const std::string& key);

}  // namespace omniloc::experiments
