#include "drivers/device_clock_mapper.h"

#include <algorithm>
#include <cmath>

namespace cairn {

Timestamp DeviceClockMapper::Map(int64_t device_time, Timestamp arrival) {
  const int64_t bucket_ns = std::max<int64_t>(1, options_.bucket.nanoseconds());
  if (started_ && (device_time < last_device_time_ || device_time - last_device_time_ > options_.max_gap.nanoseconds())) {
    buckets_.clear();
    line_valid_ = false;
    ++restarts_;
  }
  started_ = true;
  last_device_time_ = device_time;
  const int64_t difference = arrival.nanoseconds() - device_time;
  const int64_t index = device_time / bucket_ns;
  if (buckets_.empty() || buckets_.back().index != index) {
    buckets_.push_back({index, device_time, difference});
    if (static_cast<int>(buckets_.size()) > std::max(1, options_.buckets)) buckets_.erase(buckets_.begin());
    Refit();  // the finished buckets changed
  } else if (difference < buckets_.back().lowest) {
    buckets_.back().device_time = device_time;
    buckets_.back().lowest = difference;
  }
  // The current bucket is incomplete: its lowest may still fall. The line through the finished
  // ones stays under the current bucket's lowest so far.
  double offset = static_cast<double>(buckets_.back().lowest);
  if (line_valid_) {
    offset = std::min(offset, line_intercept_ + drift_ * 1e9 * (static_cast<double>(device_time) - line_t0_) * 1e-9);
  } else if (buckets_.size() == 2) {
    offset = std::min(offset, static_cast<double>(buckets_.front().lowest));
  }
  offset_s_ = offset * 1e-9;
  // As the fit settles its offset falls: never behind the previous sample (time must not run
  // backwards for the filter), never after the arrival.
  int64_t host = device_time + static_cast<int64_t>(std::llround(offset));
  if (have_output_) host = std::max(host, last_output_ + 1);
  host = std::min(host, arrival.nanoseconds());
  have_output_ = true;
  last_output_ = host;
  return Timestamp::FromNanoseconds(host);
}

void DeviceClockMapper::Refit() {
  line_valid_ = false;
  const size_t finished = buckets_.size() - 1;
  if (finished < 2) return;
  const double t0 = static_cast<double>(buckets_.front().device_time);
  double st = 0, so = 0, stt = 0, sto = 0;
  for (size_t i = 0; i < finished; ++i) {
    const double t = (static_cast<double>(buckets_[i].device_time) - t0) * 1e-9;
    const double o = static_cast<double>(buckets_[i].lowest);
    st += t;
    so += o;
    stt += t * t;
    sto += t * o;
  }
  const double n = static_cast<double>(finished);
  const double det = n * stt - st * st;
  if (!(det > 1e-12)) return;
  drift_ = (n * sto - st * so) / det * 1e-9;  // ns per s -> s per s
  line_intercept_ = (so - drift_ * 1e9 * st) / n;
  line_t0_ = t0;
  line_valid_ = true;
}

}  // namespace cairn
