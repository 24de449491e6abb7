#pragma once
// Timing statistics of one sensor stream as consumed by the pipeline: counts, rate, gaps,
// out-of-order and duplicate timestamps. Fixed size, no allocation; owned by one consumer thread.

#include <cstdint>

#include "common/timestamp.h"

namespace cairn {

class SensorStreamStats {
 public:
  // `nominal_rate_hz` > 0 enables gap detection: an interval longer than 1.5 nominal periods.
  explicit SensorStreamStats(double nominal_rate_hz = 0.0);

  void Add(Timestamp t);

  uint64_t count() const { return count_; }
  Timestamp first() const { return first_; }
  Timestamp last() const { return last_; }
  double nominal_rate_hz() const { return nominal_rate_hz_; }
  // Span between the first and the latest in-order sample.
  double duration() const;
  // (count - 1) / duration; zero with fewer than two samples.
  double mean_rate_hz() const;
  double max_gap() const { return max_gap_.seconds(); }
  uint64_t gaps() const { return gaps_; }
  uint64_t out_of_order() const { return out_of_order_; }
  uint64_t duplicates() const { return duplicates_; }

 private:
  double nominal_rate_hz_;
  Duration gap_threshold_;
  uint64_t count_ = 0;
  Timestamp first_;
  Timestamp last_;
  Duration max_gap_;
  uint64_t gaps_ = 0;
  uint64_t out_of_order_ = 0;
  uint64_t duplicates_ = 0;
};

}  // namespace cairn
