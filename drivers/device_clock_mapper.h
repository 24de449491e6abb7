#pragma once
// Maps a device's sample clock (an IMU's sample counter, a camera's tick counter) to the host's
// monotonic clock when the device cannot be synchronized (no PTP): every sample arrives at
//   arrival = device_time + offset(device_time) + delay,   delay >= 0,
// with the transport delay varying from sample to sample and the offset drifting with the two
// oscillators. The lowest arrival - device_time over each bucket of device time is the sample that
// waited least; a least-squares line through the last buckets' lowest values gives the offset and
// its drift. Host time = device time + offset, never later than the arrival nor earlier than the
// previous sample's (while the fit settles its offset falls). Device time going
// backwards (a reset) or jumping by more than `max_gap` starts the fit again, counted.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/timestamp.h"

namespace cairn {

struct DeviceClockMapperOptions {
  Duration bucket = Duration::Seconds(1.0);
  int buckets = 30;  // fitted (the drift of a crystal stays linear over half a minute)
  Duration max_gap = Duration::Seconds(5.0);
};

class DeviceClockMapper {
 public:
  explicit DeviceClockMapper(const DeviceClockMapperOptions& options = {}) : options_(options) {
    buckets_.reserve(static_cast<size_t>(std::max(1, options_.buckets)) + 1);  // none allocated per sample
  }

  // The host time of a sample taken at `device_time` (ns on the device's clock, unwrapped) that
  // arrived at `arrival`.
  Timestamp Map(int64_t device_time, Timestamp arrival);

  double offset_seconds() const { return offset_s_; }  // at the last sample
  double drift_ppm() const { return drift_ * 1e6; }
  int64_t restarts() const { return restarts_; }

 private:
  struct Bucket {
    int64_t index = 0;
    int64_t device_time = 0;  // of the lowest sample
    int64_t lowest = 0;       // arrival - device time, ns
  };

  // The least-squares line through the finished buckets, refitted only when one finishes.
  void Refit();

  DeviceClockMapperOptions options_;
  std::vector<Bucket> buckets_;  // oldest first
  bool started_ = false;
  int64_t last_device_time_ = 0;
  bool have_output_ = false;
  int64_t last_output_ = 0;  // ns, host time of the previous sample
  double offset_s_ = 0.0;
  double drift_ = 0.0;  // s per s
  bool line_valid_ = false;
  double line_t0_ = 0.0;         // ns, device time of the oldest bucket's lowest sample
  double line_intercept_ = 0.0;  // ns, offset at line_t0_
  int64_t restarts_ = 0;
};

}  // namespace cairn
