#pragma once
// Latency distribution with about 9 % resolution from 1 us to 16 s in fixed storage: recording is
// allocation and lock free (one writer), so real-time threads can keep one.

#include <array>
#include <atomic>
#include <cstdint>

#include "common/timestamp.h"

namespace cairn {

class LatencyHistogram {
 public:
  void Record(Duration d);
  uint64_t count() const { return count_; }
  // Upper edge of the bucket holding quantile q in [0, 1]; zero when empty.
  Duration Quantile(double q) const;
  Duration max() const { return Duration::Nanoseconds(max_ns_); }
  // Exact count of records longer than 1 ms, the real-time budget of a stage input: the buckets
  // are too coarse to say whether 1.05 ms was late.
  uint64_t over_1ms() const { return over_1ms_; }

 private:
  static constexpr int kPerOctave = 8;
  static constexpr int kOctaves = 24;  // 1 us .. 2^24 us
  static int Bucket(int64_t us);
  static int64_t UpperEdgeUs(int bucket);

  std::array<uint64_t, kPerOctave * kOctaves + 1> buckets_{};
  uint64_t count_ = 0;
  uint64_t over_1ms_ = 0;
  int64_t max_ns_ = 0;
};

}  // namespace cairn
