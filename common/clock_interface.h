#pragma once

#include "common/timestamp.h"

namespace cairn {

// The robot's monotonic clock. Replay and simulation substitute their own.
class ClockInterface {
 public:
  virtual ~ClockInterface() = default;
  virtual Timestamp Now() const = 0;
};

}  // namespace cairn
