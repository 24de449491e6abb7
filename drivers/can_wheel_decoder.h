#pragma once
// Turns raw CAN frames into wheel odometry samples according to CanWheelOptions. Pure and
// allocation free, so it serves the SocketCAN driver, candump log replay and the simulator's
// encoder alike.

#include <linux/can.h>

#include <array>
#include <cstdint>
#include <optional>

#include "drivers/can_wheel_options.h"
#include "hal/calibration.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

// Raw integer at the signal's place, scaled; nullopt when the frame is too short.
std::optional<double> DecodeCanSignal(const CanSignalOptions& signal, const can_frame& frame);
// The inverse, for encoders and tests: writes the value into the frame's payload.
void EncodeCanSignal(const CanSignalOptions& signal, double value, can_frame* frame);
// True when the frame's identifier (standard or extended) is the signal's.
bool CanIdMatches(const CanSignalOptions& signal, const can_frame& frame);

class CanWheelDecoder {
 public:
  enum class Result { kIgnored, kUpdated, kSampleReady, kMalformed, kErrorFrame };

  explicit CanWheelDecoder(const CanWheelOptions& options);

  // Feeds one frame received at `time`. On kSampleReady, `out` holds the latest state of all
  // wheels and which of them were refreshed since the previous sample.
  Result Feed(const can_frame& frame, Timestamp time, WheelOdometrySample* out);

  WheelCalibration calibration() const;

 private:
  std::array<const WheelCanOptions*, kMaxWheels> wheels_;
  CanWheelOptions options_;
  WheelOdometrySample state_;
};

}  // namespace cairn
