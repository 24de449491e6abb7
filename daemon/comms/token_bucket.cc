#include "daemon/comms/token_bucket.h"

#include <algorithm>

namespace cairn {

TokenBucket::TokenBucket(double rate_bytes_per_s, double burst_bytes)
    : rate_(std::max(rate_bytes_per_s, 1.0)), burst_(std::max(burst_bytes, 1.0)), balance_(burst_) {}

void TokenBucket::Refill(Timestamp now) {
  if (!started_) {
    started_ = true;
    last_ = now;
    return;
  }
  if (now <= last_) return;
  balance_ = std::min(burst_, balance_ + rate_ * (now - last_).seconds());
  last_ = now;
}

bool TokenBucket::Ready(Timestamp now) {
  Refill(now);
  return balance_ > 0.0;
}

void TokenBucket::Spend(Timestamp now, size_t bytes) {
  Refill(now);
  balance_ -= static_cast<double>(bytes);
}

Duration TokenBucket::Wait(Timestamp now) {
  Refill(now);
  if (balance_ > 0.0) return Duration();
  // Just past zero, so that Ready() holds when the wait is over.
  return Duration::Seconds((-balance_ + 1.0) / rate_);
}

double TokenBucket::balance(Timestamp now) {
  Refill(now);
  return balance_;
}

}  // namespace cairn
