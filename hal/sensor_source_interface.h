#pragma once

#include <cstddef>
#include <string>

#include "common/status.h"
#include "hal/sensor_sink.h"

namespace cairn {

// Anything that publishes HAL messages: one device driver, a replayed recording, the simulator.
class SensorSourceInterface {
 public:
  virtual ~SensorSourceInterface() = default;

  virtual std::string name() const = 0;
  // Opens the device(s) and starts publishing into `sink` from the source's own thread(s). The sink
  // must outlive the source's Stop().
  virtual Status Start(SensorSink* sink) = 0;
  // Stops publishing and joins the source's threads; idempotent.
  virtual void Stop() = 0;
  // True once a finite source (a replay) has published everything it had.
  virtual bool finished() const = 0;
  // Heap bytes the source holds for its samples (a simulator's generated streams); devices and
  // streaming replays hold next to nothing and report 0.
  virtual size_t memory_bytes() const { return 0; }
};

}  // namespace cairn
