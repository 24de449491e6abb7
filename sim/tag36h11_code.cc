#include "sim/tag36h11_code.h"

#include <string>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

namespace cairn::sim {
namespace {

// The family is immutable after creation; one instance for the process.
const apriltag_family_t& Family() {
  static const apriltag_family_t* family = tag36h11_create();
  return *family;
}

}  // namespace

int Tag36h11Count() { return static_cast<int>(Family().ncodes); }

Expected<uint64_t> Tag36h11MarkerBits(int id) {
  const apriltag_family_t& f = Family();
  if (id < 0 || id >= static_cast<int>(f.ncodes)) {
    return InvalidArgumentError("tag36h11 id " + std::to_string(id) + " is outside [0, " +
                                std::to_string(f.ncodes - 1) + "]");
  }
  // The library orders a code word's bits along its own spiral (bit_x, bit_y); data modules sit at
  // 1..6 inside the 8-module black border. Re-order them into the marker's row-major grid.
  const uint64_t word = f.codes[id];
  uint64_t bits = 0;
  for (uint32_t i = 0; i < f.nbits; ++i) {
    const uint64_t value = (word >> (f.nbits - 1 - i)) & 1u;
    const int row = static_cast<int>(f.bit_y[i]) - 1, col = static_cast<int>(f.bit_x[i]) - 1;
    bits |= value << (35 - (row * 6 + col));
  }
  return bits;
}

}  // namespace cairn::sim
