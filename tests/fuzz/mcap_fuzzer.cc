// Recordings: MCAP records, chunks (zstd, LZ4), the summary, and the calibration they carry.
#include <cstddef>
#include <cstdint>

#include "drivers/replay/mcap_replay.h"
#include "io/mcap/mcap_reader.h"
#include "tests/fuzz/fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = cairn::fuzz::WriteInputFile(data, size, ".mcap");
  cairn::McapReader reader(path);
  uint64_t bytes = 0;
  (void)reader.Scan([&](const cairn::McapChannel&, const cairn::McapMessageView& m) { bytes += m.data.size(); });
  (void)reader.ReadSummary();
  (void)cairn::McapReplay::ReadCalibration(path);
  return 0;
}
