#pragma once

#include "hal/sensor_source_interface.h"

namespace cairn {

// The camera trigger line (libgpiod): emits trigger pulses at a rate and reports each edge's
// time through SensorSink::OnTrigger, so exposure times are known even when a camera's own
// timestamps are not.
class TriggerInterface : public SensorSourceInterface {
 public:
  virtual Status SetRate(double hz) = 0;
};

}  // namespace cairn
