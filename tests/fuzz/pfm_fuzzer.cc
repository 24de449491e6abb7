// Disparity ground truth and outputs in PFM.
#include <cstddef>
#include <cstdint>

#include "stereo/pfm_io.h"
#include "tests/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)cairn::ReadPfm(cairn::fuzz::WriteInputFile(data, size, ".pfm"));
  return 0;
}
