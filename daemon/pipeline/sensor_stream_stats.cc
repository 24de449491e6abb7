#include "daemon/pipeline/sensor_stream_stats.h"

namespace cairn {

SensorStreamStats::SensorStreamStats(double nominal_rate_hz)
    : nominal_rate_hz_(nominal_rate_hz),
      gap_threshold_(nominal_rate_hz > 0.0 ? Duration::Seconds(1.5 / nominal_rate_hz)
                                           : Duration::Nanoseconds(0)) {}

void SensorStreamStats::Add(Timestamp t) {
  ++count_;
  if (count_ == 1) {
    first_ = last_ = t;
    return;
  }
  if (t == last_) {
    ++duplicates_;
    return;
  }
  if (t < last_) {
    ++out_of_order_;
    return;  // `last_` stays the newest time seen, so one late sample counts once
  }
  const Duration dt = t - last_;
  if (dt > max_gap_) max_gap_ = dt;
  if (gap_threshold_.nanoseconds() > 0 && dt > gap_threshold_) ++gaps_;
  last_ = t;
}

double SensorStreamStats::duration() const { return count_ < 2 ? 0.0 : (last_ - first_).seconds(); }

double SensorStreamStats::mean_rate_hz() const {
  const uint64_t in_order = count_ - duplicates_ - out_of_order_;
  const double d = duration();
  return (in_order < 2 || d <= 0.0) ? 0.0 : static_cast<double>(in_order - 1) / d;
}

}  // namespace cairn
