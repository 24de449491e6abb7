#include "sim/rover_can_layout.h"

namespace cairn::sim {
namespace {

CanSignalOptions Signal(int64_t id, int64_t start_byte, double scale) {
  CanSignalOptions s;
  s.id = id;
  s.extended_id = false;
  s.start_byte = start_byte;
  s.length = 2;
  s.is_signed = true;
  s.byte_order = ByteOrder::kLittleEndian;
  s.scale = scale;
  s.offset = 0.0;
  return s;
}

WheelCanOptions Wheel(int64_t id, double x, double y) {
  WheelCanOptions w;
  w.speed = Signal(id, 0, 0.001);
  w.steered = true;
  w.steering = Signal(id, 2, 0.0001);
  w.position = {x, y};
  return w;
}

}  // namespace

CanWheelOptions RoverCanLayout() {
  CanWheelOptions layout;
  layout.enabled = true;
  layout.interface = "can0";
  layout.sync_id = 0x120;
  layout.timeout = 0.2;
  // Slip on loose ground dominates the encoders' own 0.02 m/s (see configs/rover.yaml).
  layout.speed_noise = 0.06;
  layout.front_left = Wheel(0x101, 0.35, 0.33);
  layout.front_right = Wheel(0x102, 0.35, -0.33);
  layout.rear_left = Wheel(0x103, -0.35, 0.33);
  layout.rear_right = Wheel(0x104, -0.35, -0.33);
  return layout;
}

}  // namespace cairn::sim
