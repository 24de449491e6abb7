#pragma once
// The sensors' calibration as a recording stores it (cairn.msg.Calibration on /calibration): what
// a replay of that recording needs to run the estimation chain again, bit for bit as recorded.

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "common/status.h"
#include "hal/calibration.h"

namespace cairn {

struct RecordedCalibration {
  std::string robot;
  StereoCalibration stereo;
  double camera_rate_hz = 0.0;
  ImuCalibration imu;
  std::optional<WheelCalibration> wheels;  // none on robots without wheel odometry

  std::string Encode() const;
  // Refuses what no calibration can be (bad sizes, non-positive rates, non-rigid transforms, NaN),
  // naming `where`. Values are taken as stored: a replay must see the recorded doubles.
  static Expected<RecordedCalibration> Decode(std::span<const uint8_t> bytes, const std::string& where);
};

}  // namespace cairn
