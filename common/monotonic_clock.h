#pragma once

#include "common/clock_interface.h"

namespace cairn {

// CLOCK_MONOTONIC, the clock every driver stamps samples with.
class MonotonicClock final : public ClockInterface {
 public:
  Timestamp Now() const override;
};

}  // namespace cairn
