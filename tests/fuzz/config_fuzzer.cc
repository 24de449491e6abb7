// cairnd's profiles: YAML, every key checked.
#include <cstddef>
#include <cstdint>

#include "daemon/cairnd_config.h"
#include "tests/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)cairn::LoadCairndOptions(cairn::fuzz::WriteInputFile(data, size, ".yaml"), {});
  return 0;
}
