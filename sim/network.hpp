#pragma once
// A team radio network (paper 001 shares the robots' ball sightings over ZigBee): every message
// carries the time stamp its sender gave it; the network delays it by a latency plus jitter, or loses
// it, and hands it to the receiver once the receiver's clock has reached its arrival time.
//
// Randomness: the constructor takes one value from the seeded Rng passed in (the network key). The
// fate of a message (lost or not, its delay) is drawn from its own stream, derived from that key, the
// sender id and the sender's sequence number, with the same draws whatever the configuration. So
//  - the same seed gives the same arrivals;
//  - losing a packet, a sender being late, or another sender sending more or fewer messages changes
//    no other message's fate;
//  - with the same seed, raising the loss probability only removes messages (the survivors arrive at
//    the same times), because a message is lost when its own uniform draw is below the loss
//    probability.
// Times are in seconds on one shared clock (the simulation's).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "core/json_reader.hpp"
#include "core/rng.hpp"

namespace omniloc::sim {

enum class JitterKind {
  Uniform,   ///< delay = latency + U(-jitter, +jitter)
  Gaussian,  ///< delay = latency + N(0, jitter^2)
};

const char* to_string(JitterKind k);

struct NetworkConfig {
  double latency = 0.0;  ///< s, one-way delay before jitter
  double jitter = 0.0;   ///< s: half-width (Uniform) or standard deviation (Gaussian); the delay is clipped at 0
  JitterKind jitter_kind = JitterKind::Uniform;
  double loss = 0.0;     ///< probability in [0, 1] that a message never arrives

  /// Keys "latency", "jitter" (>= 0, <= 10 s), "jitter_kind" ("uniform" | "gaussian"), "loss" in [0, 1];
  /// absent keys keep `defaults`. Does not call finish() (the caller owns the object).
  static NetworkConfig from_json(JsonReader& r, const NetworkConfig& defaults);
};

/// What happens to one message.
struct Delivery {
  bool lost = false;
  double delay = 0.0;  ///< s, >= 0 (meaningful also for lost messages: it is drawn regardless)
};

/// The random part of the network, independent of the payload type.
class NetworkChannel {
 public:
  /// Takes one 64-bit value from `rng` as the network key.
  NetworkChannel(const NetworkConfig& cfg, Rng& rng);
  /// Fate of message number `seq` (0, 1, 2, ... per sender) of `sender`: a pure function of the
  /// key, sender and seq (and the configuration).
  Delivery fate(int sender, std::uint64_t seq) const;
  const NetworkConfig& config() const { return cfg_; }

 private:
  NetworkConfig cfg_;
  std::uint64_t key_;
};

template <class Payload>
struct NetMessage {
  int sender = 0;
  double stamp = 0.0;    ///< s, set by the sender: when the data was taken (e.g. the image time)
  Payload payload{};
  // Filled in by Network::send():
  double sent = 0.0;     ///< s, when it was handed to the network
  double arrival = 0.0;  ///< s, when the receiver can have it
  std::uint64_t seq = 0; ///< the sender's message counter
};

/// The network itself: send() now, receive() later.
template <class Payload>
class Network {
 public:
  Network(const NetworkConfig& cfg, Rng& rng) : channel_(cfg, rng) {}

  /// Hands `msg` to the network at time t (s). Returns false when the message is lost.
  bool send(NetMessage<Payload> msg, double t) {
    msg.seq = next_seq_[msg.sender]++;
    msg.sent = t;
    const Delivery d = channel_.fate(msg.sender, msg.seq);
    ++sent_;
    if (d.lost) {
      ++lost_;
      return false;
    }
    msg.arrival = t + d.delay;
    queue_.push_back(Entry{order_++, std::move(msg)});
    return true;
  }

  /// Every message not yet received whose arrival time is <= t, in arrival order (ties in send
  /// order). They leave the network.
  std::vector<NetMessage<Payload>> receive(double t) {
    std::vector<Entry> due;
    std::vector<Entry> keep;
    for (Entry& e : queue_) (e.msg.arrival <= t ? due : keep).push_back(std::move(e));
    queue_ = std::move(keep);
    std::stable_sort(due.begin(), due.end(), [](const Entry& a, const Entry& b) {
      return a.msg.arrival < b.msg.arrival || (a.msg.arrival == b.msg.arrival && a.order < b.order);
    });
    std::vector<NetMessage<Payload>> out;
    out.reserve(due.size());
    for (Entry& e : due) out.push_back(std::move(e.msg));
    delivered_ += out.size();
    return out;
  }

  std::size_t sent() const { return sent_; }
  std::size_t lost() const { return lost_; }
  std::size_t delivered() const { return delivered_; }
  std::size_t in_flight() const { return queue_.size(); }
  const NetworkConfig& config() const { return channel_.config(); }

 private:
  struct Entry {
    std::uint64_t order;
    NetMessage<Payload> msg;
  };
  NetworkChannel channel_;
  std::map<int, std::uint64_t> next_seq_;
  std::vector<Entry> queue_;
  std::uint64_t order_ = 0;
  std::size_t sent_ = 0, lost_ = 0, delivered_ = 0;
};

}  // namespace omniloc::sim
