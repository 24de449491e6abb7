#pragma once
// Turns the kernel's timestamps of a trigger line's edges into TriggerEvents.
//
// Clock: the GPIO character device's v1 interface (the one libgpiod 1.6 uses, which has no flag to
// choose) stamps edges with CLOCK_MONOTONIC since Linux 5.7 and with CLOCK_REALTIME before. Each
// edge's clock is recognized from both clocks read right after it was read (an edge is stamped
// before it can be read, and never long before), and a realtime stamp is moved onto the monotonic
// clock by the two clocks' difference at that moment.
//
// Lost edges: that interface carries no sequence number (v2's line_seqno is not in libgpiod 1.6),
// so losses are found by time alone. With a known rate, a gap of more than 1.5 periods holds
// round(gap / period) - 1 missed edges, and the sequence skips them: an edge's sequence stays the
// number of the frame it starts. Without a rate, every edge is the next.

#include <cstdint>

#include "common/timestamp.h"
#include "hal/trigger_event.h"

namespace cairn {

enum class TriggerEdgeClock { kMonotonic, kRealtime, kArrival };

struct TriggerEdge {
  TriggerEvent event;
  uint64_t missed = 0;  // edges lost just before this one
  TriggerEdgeClock clock = TriggerEdgeClock::kMonotonic;
  // False when the edge is not later than the one before (a realtime clock stepped back): it is
  // dropped and the sequence does not advance.
  bool valid = true;
};

class TriggerEdgeSequencer {
 public:
  // 0: unknown, no losses are inferred.
  void SetRate(double hz) { rate_hz_ = hz; }
  // After a reconnection: the gap to the next edge is an outage, not lost edges.
  void Restart() { have_last_ = false; }

  // `kernel_ns` as the kernel stamped it; both clocks read after the edge was read.
  TriggerEdge Add(int64_t kernel_ns, Timestamp monotonic_now, int64_t realtime_now_ns);

  uint64_t next_sequence() const { return next_sequence_; }

 private:
  double rate_hz_ = 0.0;
  bool have_last_ = false;
  Timestamp last_;
  uint64_t next_sequence_ = 0;
};

}  // namespace cairn
