#pragma once

#include <cstdint>

#include "common/timestamp.h"
#include "hal/image.h"

namespace cairn {

// A hardware-synchronized stereo pair. `time` is the middle of the exposure on the robot's
// monotonic clock: the filter clones its state at exactly this instant.
struct StereoFrame {
  Timestamp time;
  Duration exposure;          // exposure time; zero when the device does not report it
  uint64_t frame_counter = 0; // from the device; gaps reveal dropped frames
  Image left;
  Image right;
};

}  // namespace cairn
