#pragma once
// How the fuzz targets that decode a teammate's items name graph variables.

#include <cstdint>
#include <string>

#include "daemon/comms/team_item_codec.h"

namespace cairn::fuzz {

// Graph names for a team of robots "a" and "b": any other robot has no letter.
inline TeamItemCodec::Names TeamNames() {
  TeamItemCodec::Names names;
  names.letter_of = [](const std::string& robot) { return robot == "a" ? 'a' : robot == "b" ? 'b' : '\0'; };
  names.frame_index = [](const std::string&, uint32_t incarnation, uint64_t frame) {
    return (uint64_t{incarnation} << 40) + frame;
  };
  return names;
}

}  // namespace cairn::fuzz
