#pragma once
// The bytes that open and close every MCAP file (format version 0).

#include <cstdint>

namespace cairn {

inline constexpr uint8_t kMcapMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

}  // namespace cairn
