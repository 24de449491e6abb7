#pragma once
// The machine's own scheduling latency as cyclictest (rt-tests) measured it, read from the file
// its --json option writes: one thread's 1-us histogram, its cycle count and exact maximum.

#include <cstdint>
#include <string>

#include "common/status.h"

namespace cairn::tools {

struct CyclictestResult {
  uint64_t cycles = 0;
  double median_us = 0.0;
  double p999_us = 0.0;
  double max_us = 0.0;
  uint64_t over_1ms = 0;  // wake-ups later than 1 ms (from the histogram; overflows count)
};

class CyclictestReader {
 public:
  // Thread 0 of `path`. The histogram must have been asked for (-h US); wake-ups beyond its range
  // are counted as later than its last bucket. Errors name the file and the missing part.
  static Expected<CyclictestResult> Read(const std::string& path);
  static Expected<CyclictestResult> Parse(const std::string& json_text, const std::string& source_name);
};

}  // namespace cairn::tools
