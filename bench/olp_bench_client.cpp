// The smallest useful olp/1 client (docs/protocol.md), for bench/protocol_bench.cpp: it parses every
// message in full (as any client must) and dead-reckons, so the benchmark measures the protocol's
// cost (pipes, framing, JSON both ways, the image copy), not a localizer's.
// usage: olp_bench_client [image]   ("image": ask for the raw image in every frame)
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

int main(int argc, char** argv) {
  const bool want_image = argc > 1 && std::string(argv[1]) == "image";
  std::ios::sync_with_stdio(false);
  std::string line;
  std::vector<char> part;
  double x = 0, y = 0, th = 0;
  std::string out;
  while (std::getline(std::cin, line)) {
    const nlohmann::json m = nlohmann::json::parse(line);
    if (const auto b = m.find("binary"); b != m.end())
      for (const auto& p : *b) {
        part.resize(p["bytes"].get<std::size_t>());
        if (!std::cin.read(part.data(), static_cast<std::streamsize>(part.size()))) return 1;
      }
    const std::string type = m["type"];
    if (type == "hello") {
      out = nlohmann::json{{"type", "ready"}, {"name", "olp_bench"}, {"version", "1"}, {"needs_start_pose", true}, {"wants_image", want_image}}.dump();
    } else if (type == "reset") {
      if (m["start"].is_array()) x = m["start"][0], y = m["start"][1], th = m["start"][2];
      continue;
    } else if (type == "frame") {
      const double dx = m["odometry"][0], dy = m["odometry"][1], dth = m["odometry"][2];
      const double c = std::cos(th), s = std::sin(th);
      x = x + c * dx - s * dy;
      y = y + s * dx + c * dy;
      th += dth;
      out = nlohmann::json{{"type", "estimate"}, {"k", m["k"]}, {"pose", {x, y, th}}, {"valid", true}}.dump();
    } else if (type == "end") {
      return 0;
    } else {
      continue;
    }
    out += '\n';
    std::cout.write(out.data(), static_cast<std::streamsize>(out.size()));
    std::cout.flush();
  }
  return 1;  // end of input before "end"
}
