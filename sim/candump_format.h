#pragma once
// candump log lines ("(1700000000.123456) can0 101#E8030000", as written by `candump -L` and read
// by `canplayer`), so that simulated wheel encoders can be replayed through the SocketCAN path.

#include <linux/can.h>

#include <string>

#include "common/status.h"
#include "common/timestamp.h"

namespace cairn::sim {

struct CandumpRecord {
  Timestamp time;
  std::string interface;
  can_frame frame{};
};

std::string FormatCandumpLine(Timestamp time, const std::string& interface, const can_frame& frame);
// Parses one line; the error names the problem (callers add file and line).
Expected<CandumpRecord> ParseCandumpLine(const std::string& line);

}  // namespace cairn::sim
