#pragma once
// An item in one of the pipeline's queues, with the time it was published (for the latency from
// publication to consumption).

#include <cstdint>

namespace cairn {

template <class T>
struct Queued {
  int64_t enqueued_ns = 0;  // CLOCK_MONOTONIC
  T value{};
};

}  // namespace cairn
