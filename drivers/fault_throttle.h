#pragma once
// Counts a fault that can recur with every sample (a lost edge, a frame without its edge) and
// says when to report it: at most once per interval, with how many occurred since the last
// report, so a broken wire costs one message a second instead of one per frame.

#include <cstdint>
#include <utility>

#include "common/timestamp.h"

namespace cairn {

class FaultThrottle {
 public:
  explicit FaultThrottle(Duration interval = Duration::Seconds(1.0)) : interval_(interval) {}

  // Counts `n` more occurrences (0 flushes the pending ones once the interval has passed) and
  // returns how many to report now; 0 means nothing to report yet.
  uint64_t Add(uint64_t n, Timestamp now) {
    pending_ += n;
    if (pending_ == 0 || (reported_ && now - last_report_ < interval_)) return 0;
    reported_ = true;
    last_report_ = now;
    return std::exchange(pending_, 0);
  }

 private:
  Duration interval_;
  uint64_t pending_ = 0;
  bool reported_ = false;
  Timestamp last_report_;
};

}  // namespace cairn
