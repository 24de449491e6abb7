#pragma once

#include <array>
#include <cstdint>

#include "common/timestamp.h"

namespace cairn {

inline constexpr int kMaxWheels = 4;

// Per-wheel state decoded from the platform controller (CAN). Speeds are wheel-ground contact
// speeds in m/s (positive forward), steering angles in rad (positive turns left, about body z).
struct WheelState {
  double speed = 0.0;
  double steering_angle = 0.0;
};

struct WheelOdometrySample {
  Timestamp time;
  std::array<WheelState, kMaxWheels> wheels{};
  uint8_t wheel_count = 0;
  // Bit i set when wheel i's speed was refreshed since the previous sample (stale values are
  // repeated so that consumers always see a full set).
  uint8_t fresh_mask = 0;
};

}  // namespace cairn
