#include "drivers/trigger_edge_sequencer.h"

#include <cmath>

namespace cairn {
namespace {

// How long an edge may wait in the kernel's queue before it is read (a reader stalled by a loaded
// machine), and how far a stamp may lead the clock read after it (none; a little for safety).
constexpr int64_t kEdgeMaxAgeNs = 10'000'000'000;
constexpr int64_t kEdgeLeadNs = 1'000'000;

bool StampFits(int64_t stamp_ns, int64_t now_ns) {
  return stamp_ns <= now_ns + kEdgeLeadNs && stamp_ns >= now_ns - kEdgeMaxAgeNs;
}

}  // namespace

TriggerEdge TriggerEdgeSequencer::Add(int64_t kernel_ns, Timestamp monotonic_now, int64_t realtime_now_ns) {
  TriggerEdge edge;
  if (StampFits(kernel_ns, monotonic_now.nanoseconds())) {
    edge.event.time = Timestamp::FromNanoseconds(kernel_ns);
  } else if (StampFits(kernel_ns, realtime_now_ns)) {
    edge.clock = TriggerEdgeClock::kRealtime;
    edge.event.time = monotonic_now - Duration::Nanoseconds(realtime_now_ns - kernel_ns);
  } else {
    edge.clock = TriggerEdgeClock::kArrival;  // neither clock: the stamp is useless
    edge.event.time = monotonic_now;
  }
  if (have_last_ && edge.event.time <= last_) {
    edge.valid = false;
    return edge;
  }
  if (have_last_ && rate_hz_ > 0.0) {
    const double periods = (edge.event.time - last_).seconds() * rate_hz_;
    if (periods > 1.5) edge.missed = static_cast<uint64_t>(std::llround(periods)) - 1;
  }
  have_last_ = true;
  last_ = edge.event.time;
  edge.event.sequence = next_sequence_ + edge.missed;
  next_sequence_ = edge.event.sequence + 1;
  return edge;
}

}  // namespace cairn
