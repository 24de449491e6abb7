// The calibration a recording carries.
#include <cstddef>
#include <cstdint>

#include "drivers/replay/recorded_calibration.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)cairn::RecordedCalibration::Decode({data, size}, "fuzz");
  return 0;
}
