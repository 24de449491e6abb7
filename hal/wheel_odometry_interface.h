#pragma once

#include "hal/calibration.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

// Wheel speeds and steering angles from the platform controller (SocketCAN, replay, simulator);
// samples arrive through SensorSink::OnWheelOdometry.
class WheelOdometryInterface : public SensorSourceInterface {
 public:
  virtual WheelCalibration calibration() const = 0;
};

}  // namespace cairn
