// A teammate's items: the first byte chooses the kind, the rest is the payload.
#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/comms/team_item_codec.h"
#include "tests/fuzz/team_names.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  cairn::StoreItem item;
  item.key.origin = "b";
  item.key.lane = 0;
  item.key.seq = 1;
  item.kind = static_cast<uint16_t>(data[0] % 9);
  item.payload.assign(reinterpret_cast<const char*>(data + 1), size - 1);
  const cairn::TeamItemCodec::Names names = cairn::fuzz::TeamNames();
  (void)cairn::TeamItemCodec::Decode(item, names);
  (void)cairn::TeamItemCodec::IncarnationOf(item);
  return 0;
}
