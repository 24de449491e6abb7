#pragma once
// Wall time spent so far, for the timings that reports and benchmarks print.

#include <chrono>

namespace cairn {

inline double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace cairn
