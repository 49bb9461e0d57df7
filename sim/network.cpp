// Team radio network with latency, jitter and loss. See network.hpp.
#include "sim/network.hpp"

#include <algorithm>

namespace omniloc::sim {

const char* to_string(JitterKind k) {
  switch (k) {
    case JitterKind::Uniform: return "uniform";
    case JitterKind::Gaussian: return "gaussian";
  }
  return "unknown";
}

NetworkConfig NetworkConfig::from_json(JsonReader& r, const NetworkConfig& defaults) {
  NetworkConfig c;
  c.latency = r.number("latency", defaults.latency, 0.0, 10.0);
  c.jitter = r.number("jitter", defaults.jitter, 0.0, 10.0);
  const std::string kind = r.string("jitter_kind", std::string(to_string(defaults.jitter_kind)), {"uniform", "gaussian"});
  c.jitter_kind = kind == "gaussian" ? JitterKind::Gaussian : JitterKind::Uniform;
  c.loss = r.number("loss", defaults.loss, 0.0, 1.0);
  return c;
}

NetworkChannel::NetworkChannel(const NetworkConfig& cfg, Rng& rng) : cfg_(cfg), key_(rng.next_u64()) {}

Delivery NetworkChannel::fate(int sender, std::uint64_t seq) const {
  // One stream per (sender, seq); the draws are taken in a fixed order and all of them always, so a
  // message's fate does not depend on the configuration's other fields or on any other message.
  const std::uint64_t s = splitmix64(key_ ^ splitmix64(static_cast<std::uint64_t>(static_cast<std::uint32_t>(sender)) * 0x9E3779B97F4A7C15ULL +
                                                      splitmix64(seq + 1)));
  Rng rng(s);
  const double u_loss = rng.uniform();
  const double u_jitter = rng.uniform(-1.0, 1.0);
  const double z_jitter = rng.normal();
  Delivery d;
  d.lost = u_loss < cfg_.loss;
  const double j = cfg_.jitter_kind == JitterKind::Gaussian ? cfg_.jitter * z_jitter : cfg_.jitter * u_jitter;
  d.delay = std::max(0.0, cfg_.latency + j);
  return d;
}

}  // namespace omniloc::sim
