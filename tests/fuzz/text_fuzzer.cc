// Small text formats a user or a teammate's file hands over: the first byte chooses the parser
// (tag carrier table, tag error table, team file, candump line).
#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/comms/team_file.h"
#include "detection/tag_carrier_table.h"
#include "detection/tag_error_table.h"
#include "sim/candump_format.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 4) {
    case 0: (void)cairn::TagCarrierTable::Parse(text, "fuzz"); break;
    case 1: (void)cairn::TagErrorTable::Parse(text, "fuzz"); break;
    case 2: (void)cairn::TeamFile::Parse(text, "fuzz"); break;
    default: (void)cairn::sim::ParseCandumpLine(text); break;
  }
  return 0;
}
