// Submaps as files and as teammates send them.
#include <cstddef>
#include <cstdint>

#include "mapping/submap_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)cairn::SubmapCodec::Decode({data, size});
  return 0;
}
