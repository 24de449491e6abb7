// Image files and recorded compressed images (PNG, JPEG, PGM/PPM) in every read mode.
#include <cstddef>
#include <cstdint>

#include "io/image_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using cairn::ImageReadMode;
  for (ImageReadMode mode : {ImageReadMode::kUnchanged, ImageReadMode::kGray8, ImageReadMode::kGrayAnyDepth}) {
    (void)cairn::ImageCodec::Decode({data, size}, mode, "fuzz");
  }
  return 0;
}
