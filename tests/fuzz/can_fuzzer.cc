// Wheel encoder frames off a CAN bus, with the rover's layout: 16-byte records of identifier
// (4 bytes), length (1), payload (8), 3 bytes unused.
#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "drivers/can_wheel_decoder.h"
#include "sim/rover_can_layout.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  cairn::CanWheelDecoder decoder(cairn::sim::RoverCanLayout());
  cairn::WheelOdometrySample sample;
  int64_t ns = 0;
  for (size_t at = 0; at + 16 <= size; at += 16) {
    can_frame frame{};
    std::memcpy(&frame.can_id, data + at, 4);
    frame.can_dlc = data[at + 4];  // may exceed 8: the decoder must not trust it
    std::memcpy(frame.data, data + at + 5, 8);
    ns += 1000000 + data[at + 13] * 100000;
    (void)decoder.Feed(frame, cairn::Timestamp::FromNanoseconds(ns), &sample);
  }
  return 0;
}
