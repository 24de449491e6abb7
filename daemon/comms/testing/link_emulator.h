#pragma once
// One direction of a radio link between two robots, in user space and simulated time (the kernel's
// netem is not available everywhere): messages are lost at random, wait behind each other for the
// link's bandwidth, arrive after a delay with jitter (which reorders them), and nothing passes
// during outages. Deterministic for a seed.

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "common/timestamp.h"

namespace cairn {

struct LinkProfile {
  Duration delay;                 // one way
  Duration jitter;                // uniform in [0, jitter] on top of the delay
  double bytes_per_s = 0.0;       // 0: unlimited
  double loss = 0.0;              // probability a message is lost
  std::vector<std::pair<Timestamp, Timestamp>> outages;  // [begin, end): everything is lost
  uint64_t seed = 1;
};

struct LinkCounters {
  uint64_t sent = 0;
  uint64_t delivered = 0;
  uint64_t lost = 0;
  uint64_t lost_in_outage = 0;
  uint64_t reordered = 0;  // delivered before a message sent earlier
  uint64_t bytes = 0;      // delivered
};

class LinkEmulator {
 public:
  explicit LinkEmulator(LinkProfile profile);

  void Send(Timestamp now, std::string message);
  // Messages whose arrival time has come, in arrival order.
  std::vector<std::string> Deliver(Timestamp now);
  bool InOutage(Timestamp t) const;
  const LinkCounters& counters() const { return counters_; }
  size_t in_flight() const { return queue_.size(); }

 private:
  struct InFlight {
    Timestamp arrival;
    uint64_t order = 0;
    std::string message;
  };

  LinkProfile profile_;
  std::mt19937_64 rng_;
  Timestamp wire_free_;  // when the link finishes sending what it has
  uint64_t sent_order_ = 0;
  uint64_t last_delivered_order_ = 0;
  std::vector<InFlight> queue_;
  LinkCounters counters_;
};

}  // namespace cairn
