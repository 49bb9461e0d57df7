#include "localization/vision/colour_table.hpp"

#include <algorithm>
#include <array>
#include <deque>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/atomic_file.hpp"
#include "core/error.hpp"
#include "core/json_reader.hpp"

namespace omniloc {

std::string colour_class_name(std::uint8_t c) {
  switch (c) {
    case kFieldGreen: return "green";
    case kLineWhite: return "white";
    case kBallOrange: return "orange";
    case kObstacleBlack: return "black";
    case kOwnBody: return "body";
    case kYellow: return "yellow";
    case kBlue: return "blue";
    case kRed: return "red";
    default: return "unknown";
  }
}

ColourClass landmark_colour_class(const std::string& name) {
  if (name == "yellow") return kYellow;
  if (name == "blue") return kBlue;
  if (name == "red") return kRed;
  return kUnknown;
}

ColourTable::ColourTable(int bits) : bits_(bits), lut_(std::size_t{1} << (3 * bits), kUnknown) {}

void ColourTable::learn(const std::vector<Image>& images, const std::vector<Image>& labels, int min_count, int fill_radius) {
  const std::size_t cells = lut_.size();
  std::vector<std::array<std::uint32_t, kNumClasses>> votes(cells);
  for (auto& v : votes) v.fill(0);
  const int s = 8 - bits_;
  for (std::size_t k = 0; k < images.size() && k < labels.size(); ++k) {
    const Image& im = images[k];
    const Image& lb = labels[k];
    for (std::size_t i = 0; i + 2 < im.rgb.size(); i += 3) {
      const std::uint8_t c = lb.rgb[i];
      if (c == kUnknown || c >= kNumClasses) continue;
      const std::size_t idx = (static_cast<std::size_t>(im.rgb[i] >> s) << (2 * bits_)) | (static_cast<std::size_t>(im.rgb[i + 1] >> s) << bits_) |
                              static_cast<std::size_t>(im.rgb[i + 2] >> s);
      ++votes[idx][c];
    }
  }
  // Majority vote per cell, then breadth-first filling of empty cells from learned neighbours.
  std::deque<std::pair<std::size_t, int>> frontier;
  for (std::size_t i = 0; i < cells; ++i) {
    const auto& v = votes[i];
    const auto best = std::max_element(v.begin(), v.end());
    if (*best >= static_cast<std::uint32_t>(min_count)) {
      lut_[i] = static_cast<std::uint8_t>(best - v.begin());
      frontier.emplace_back(i, 0);
    } else {
      lut_[i] = kUnknown;
    }
  }
  const int n = 1 << bits_;
  std::vector<bool> done(cells, false);
  for (const auto& f : frontier) done[f.first] = true;
  while (!frontier.empty()) {
    const auto [i, d] = frontier.front();
    frontier.pop_front();
    if (d >= fill_radius) continue;
    const int r = static_cast<int>(i >> (2 * bits_)), g = static_cast<int>((i >> bits_) & (n - 1)), b = static_cast<int>(i & (n - 1));
    const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& o : nb) {
      const int rr = r + o[0], gg = g + o[1], bb = b + o[2];
      if (rr < 0 || gg < 0 || bb < 0 || rr >= n || gg >= n || bb >= n) continue;
      const std::size_t j = (static_cast<std::size_t>(rr) << (2 * bits_)) | (static_cast<std::size_t>(gg) << bits_) | static_cast<std::size_t>(bb);
      if (done[j]) continue;
      done[j] = true;
      lut_[j] = lut_[i];
      frontier.emplace_back(j, d + 1);
    }
  }
}

void ColourTable::save(const std::string& path) const {
  const nlohmann::json header{{"format", "omniloc-colour-table"}, {"version", 1}, {"bits", bits_}, {"field", field}};
  std::string out = header.dump() + "\n";
  out.append(reinterpret_cast<const char*>(lut_.data()), lut_.size());
  write_file_atomic(path, out);
}

ColourTable ColourTable::load(const std::string& path, const std::string& expected_field) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, "no readable file", "a colour table written by omniloc colour-calibrate");
  std::string line;
  std::getline(in, line);
  nlohmann::json h;
  try {
    h = nlohmann::json::parse(line);
  } catch (const std::exception&) {
    throw ConfigError(path, "no colour-table header", "a colour table written by omniloc colour-calibrate");
  }
  if (h.value("format", "") != "omniloc-colour-table" || h.value("version", 0) != 1)
    throw ConfigError(path, json_brief(h), "format omniloc-colour-table version 1");
  const int bits = h.value("bits", 0);
  if (bits < 3 || bits > 8) throw ConfigError(path + "#bits", std::to_string(bits), "3 to 8 bits per channel");
  ColourTable t(bits);
  t.field = h.value("field", "");
  if (!expected_field.empty() && t.field != expected_field)
    throw ConfigError(path + "#field", "\"" + t.field + "\"", "a colour table learned on this field (\"" + expected_field + "\")");
  in.read(reinterpret_cast<char*>(t.lut_.data()), static_cast<std::streamsize>(t.lut_.size()));
  if (in.gcount() != static_cast<std::streamsize>(t.lut_.size()))
    throw ConfigError(path, "a truncated table (" + std::to_string(in.gcount()) + " bytes)", std::to_string(t.lut_.size()) + " table bytes");
  return t;
}

}  // namespace omniloc
