#include "daemon/comms/testing/link_emulator.h"

#include <algorithm>

namespace cairn {

LinkEmulator::LinkEmulator(LinkProfile profile) : profile_(std::move(profile)), rng_(profile_.seed) {}

bool LinkEmulator::InOutage(Timestamp t) const {
  return std::any_of(profile_.outages.begin(), profile_.outages.end(),
                     [t](const auto& o) { return t >= o.first && t < o.second; });
}

void LinkEmulator::Send(Timestamp now, std::string message) {
  ++counters_.sent;
  const uint64_t order = ++sent_order_;
  if (InOutage(now)) {
    ++counters_.lost_in_outage;
    return;
  }
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  // The bytes occupy the link even when the message is then lost.
  Timestamp start = std::max(now, wire_free_);
  if (profile_.bytes_per_s > 0.0) {
    wire_free_ = start + Duration::Seconds(static_cast<double>(message.size()) / profile_.bytes_per_s);
  } else {
    wire_free_ = start;
  }
  if (uniform(rng_) < profile_.loss) {
    ++counters_.lost;
    return;
  }
  const Duration jitter = Duration::Seconds(uniform(rng_) * profile_.jitter.seconds());
  queue_.push_back(InFlight{wire_free_ + profile_.delay + jitter, order, std::move(message)});
}

std::vector<std::string> LinkEmulator::Deliver(Timestamp now) {
  std::stable_sort(queue_.begin(), queue_.end(),
                   [](const InFlight& a, const InFlight& b) { return a.arrival < b.arrival; });
  std::vector<std::string> out;
  size_t n = 0;
  while (n < queue_.size() && queue_[n].arrival <= now) {
    // A message that arrives inside an outage is lost too.
    if (InOutage(queue_[n].arrival)) {
      ++counters_.lost_in_outage;
    } else {
      if (queue_[n].order < last_delivered_order_) ++counters_.reordered;
      last_delivered_order_ = std::max(last_delivered_order_, queue_[n].order);
      counters_.bytes += queue_[n].message.size();
      ++counters_.delivered;
      out.push_back(std::move(queue_[n].message));
    }
    ++n;
  }
  queue_.erase(queue_.begin(), queue_.begin() + static_cast<long>(n));
  return out;
}

}  // namespace cairn
