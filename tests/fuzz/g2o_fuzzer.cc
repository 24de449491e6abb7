// Pose graphs in g2o text (benchmark files, `cairn graph`).
#include <cstddef>
#include <cstdint>
#include <string>

#include "estimation/graph/g2o_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  cairn::PoseGraph graph;
  (void)cairn::ParseG2o(std::string(reinterpret_cast<const char*>(data), size), "fuzz", graph);
  return 0;
}
