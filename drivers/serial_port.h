#pragma once
// A serial port opened raw for the drivers that read one (Xsens IMU, NMEA GNSS receiver): 8N1,
// no flow control, non-blocking, at one of the standard rates.

#include <cstdint>
#include <string>

#include "common/status.h"

namespace cairn {

class SerialPort {
 public:
  // Opens `device` raw 8N1 at `baud`, non-blocking; the caller owns the descriptor.
  static Expected<int> Open(const std::string& device, int64_t baud);
  static bool IsStandardBaud(int64_t baud);
};

}  // namespace cairn
