#pragma once
// The simulated rover's platform controller: where it puts each wheel's speed and steering angle
// in its CAN frames. Built in, as the default world is, so `cairn sim` runs anywhere; the rover
// profile (configs/rover.yaml, `can:`) states the same layout for cairnd, and a test keeps the
// two equal.

#include "drivers/can_wheel_options.h"

namespace cairn::sim {

// One frame per wheel (0x101 front left .. 0x104 rear right): speed in mm/s at bytes 0-1,
// steering in 1e-4 rad at bytes 2-3, little-endian int16; frame 0x120 closes each 100 Hz cycle.
CanWheelOptions RoverCanLayout();

}  // namespace cairn::sim
