#pragma once

#include <cstdint>

#include "common/timestamp.h"

namespace cairn {

// A camera trigger edge seen on a GPIO line: the exposure start of frame `sequence`.
struct TriggerEvent {
  Timestamp time;
  uint64_t sequence = 0;
};

}  // namespace cairn
