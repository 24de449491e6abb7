#pragma once

#include "common/timestamp.h"
#include "hal/calibration.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

enum class TriggerMode { kFreeRunning, kExternal };

// A hardware-synchronized stereo camera pair (V4L2, GenICam/Aravis, replay, simulator).
// Frames arrive through SensorSink::OnStereo.
class StereoCameraInterface : public SensorSourceInterface {
 public:
  virtual StereoCalibration calibration() const = 0;
  // Zero selects automatic exposure.
  virtual Status SetExposure(Duration exposure) = 0;
  virtual Status SetTriggerMode(TriggerMode mode) = 0;
};

}  // namespace cairn
