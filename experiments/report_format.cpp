#include "experiments/report_format.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <thread>

#include "core/angles.hpp"
#include "core/atomic_file.hpp"
#include "core/install_paths.hpp"

namespace omniloc::experiments {

std::string machine_text() {
  std::string model = "unknown CPU";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

std::string mm(double metres, int prec) { return std::isfinite(metres) ? strprintf("%.*f", prec, 1000.0 * metres) : std::string("n/a"); }

std::string deg(double rad, int prec) { return std::isfinite(rad) ? strprintf("%.*f", prec, rad * 180.0 / kPi) : std::string("n/a"); }

Json json_number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

std::string md_row(const std::vector<std::string>& cells) {
  std::string s = "|";
  for (const auto& c : cells) s += " " + c + " |";
  return s + "\n";
}

std::string md_header(const std::vector<std::string>& columns) {
  std::string rule = "|";
  for (std::size_t i = 0; i < columns.size(); ++i) rule += "---|";
  return md_row(columns) + rule + "\n";
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return std::nan("");
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double sd(const std::vector<double>& v) {
  if (v.size() < 2) return std::nan("");
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  const double hi = v[h];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
}

double quantile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}

double finite_mean(const std::vector<double>& v) {
  double s = 0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n ? s / n : std::nan("");
}

double finite_max(const std::vector<double>& v) {
  double m = std::nan("");
  for (double x : v)
    if (std::isfinite(x)) m = std::isfinite(m) ? std::max(m, x) : x;
  return m;
}

void RunningStat::add(double x) {
  n += 1;
  const double d = x - mean;
  mean += d / n;
  m2 += d * (x - mean);
}

double RunningStat::sd() const { return n > 1 ? std::sqrt(m2 / (n - 1)) : 0.0; }

double RunningStat::se() const { return n > 1 ? sd() / std::sqrt(n) : 0.0; }

std::string papers_json_file() { return (share_dir() / "results/reference/papers.json").string(); }

Json read_published(std::string* error) {
  try {
    return Json::parse(read_file(papers_json_file()));
  } catch (const std::exception& e) {
    if (error) *error = std::string("cannot read published numbers: ") + e.what();
    return Json::object();
  }
}

double published_number(const Json& papers, const std::string& group, const std::string& key) {
  if (papers.contains(group) && papers[group].contains(key) && papers[group][key].is_number()) return papers[group][key].get<double>();
  return std::nan("");
}

}  // namespace omniloc::experiments
