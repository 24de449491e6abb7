#pragma once

#include "hal/calibration.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

// An inertial measurement unit; samples arrive through SensorSink::OnImu.
class ImuInterface : public SensorSourceInterface {
 public:
  virtual ImuCalibration calibration() const = 0;
};

}  // namespace cairn
