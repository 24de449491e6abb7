// Bytes off an Xsens IMU's serial line: the Xbus framer on the stream, fed in chunks whose sizes
// the input's first byte picks, and the MTData2 decoder on every message that frames.
#include <cstddef>
#include <cstdint>
#include <span>

#include "drivers/mtdata2_decoder.h"
#include "drivers/xbus_framer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const size_t chunk = 1 + data[0] % 64;
  cairn::XbusFramer framer;
  for (size_t at = 1; at < size; at += chunk) {
    const size_t n = at + chunk <= size ? chunk : size - at;
    framer.Feed(std::span<const uint8_t>(data + at, n), [](const cairn::XbusMessage& m) {
      if (m.mid == cairn::Mtdata2Decoder::kMid) (void)cairn::Mtdata2Decoder::Decode(m.payload);
    });
  }
  return 0;
}
