#pragma once
// The published AprilTag 36h11 code words, laid out for the simulator's markers. The words come
// from the apriltag library at run time (not from a copied table), so rendered markers decode
// with any tag36h11 detector.

#include <cstdint>

#include "common/status.h"

namespace cairn::sim {

// Number of tag36h11 code words (valid ids are 0 .. count - 1).
int Tag36h11Count();

// The 6 x 6 data bits of tag36h11 `id`, row-major from the marker's top-left module, most
// significant bit first (the layout SimMarker::bits uses); 1 = white. Out-of-range ids are an error.
Expected<uint64_t> Tag36h11MarkerBits(int id);

}  // namespace cairn::sim
