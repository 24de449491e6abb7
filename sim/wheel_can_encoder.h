#pragma once
// Simulated platform controller of a four-wheel-steered rover: wheel speeds and steering angles
// follow from the body's true motion (rigid-body kinematics at each contact point), encoders see
// slip and noise, and every cycle is sent as CAN frames in the layout the SocketCAN driver decodes
// (drivers/can_wheel_options.h), closed by the sync frame.

#include <linux/can.h>

#include <cstdint>
#include <string>
#include <vector>

#include "common/timestamp.h"
#include "drivers/can_wheel_options.h"
#include "hal/wheel_odometry_sample.h"
#include "sim/bspline_trajectory.h"

namespace cairn::sim {

struct TimedCanFrame {
  Timestamp time;
  can_frame frame{};
};

struct WheelCanStream {
  std::vector<WheelOdometrySample> reported;  // what the controller meant to send, per cycle
  std::vector<TimedCanFrame> frames;
};

class WheelCanEncoder {
 public:
  // `contact_height` is the wheel contact point's z in the body frame.
  WheelCanEncoder(const CanWheelOptions& layout, double contact_height, uint64_t seed);

  WheelCanStream Generate(const BSplineTrajectory& trajectory, Timestamp start, double duration,
                          double rate_hz) const;

 private:
  CanWheelOptions layout_;
  double contact_height_;
  uint64_t seed_;
};

}  // namespace cairn::sim
