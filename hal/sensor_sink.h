#pragma once

#include "hal/device_fault.h"
#include "hal/gnss_fix.h"
#include "hal/imu_sample.h"
#include "hal/stereo_frame.h"
#include "hal/trigger_event.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

// Where drivers, replay and the simulator publish. The same messages come from all three, so the
// algorithms never know which one is behind them. Calls come from driver threads and must not
// block in live operation (the daemon's implementation pushes into bounded queues and counts
// drops); a deterministic replay may block until the pipeline has consumed the sample.
class SensorSink {
 public:
  virtual ~SensorSink() = default;
  virtual void OnImu(const ImuSample& sample) = 0;
  virtual void OnStereo(const StereoFrame& frame) = 0;
  virtual void OnWheelOdometry(const WheelOdometrySample& sample) = 0;
  virtual void OnTrigger(const TriggerEvent& event) = 0;
  virtual void OnGnss(const GnssFix& fix) = 0;
  virtual void OnDeviceFault(const DeviceFault& fault) = 0;
};

}  // namespace cairn
