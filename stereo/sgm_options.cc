#include "stereo/sgm_options.h"

#include <algorithm>
#include <string>

namespace cairn {

Status SgmOptions::Validate() const {
  if (num_disparities < 16 || num_disparities % 16 != 0) {
    return InvalidArgumentError("sgm num_disparities must be a positive multiple of 16, got " +
                                std::to_string(num_disparities));
  }
  if (census_width % 2 == 0 || census_height % 2 == 0) {
    return InvalidArgumentError("sgm census window must have odd sides, got " +
                                std::to_string(census_width) + "x" + std::to_string(census_height));
  }
  if (census_bits() > 32) {
    return InvalidArgumentError("sgm census window " + std::to_string(census_width) + "x" +
                                std::to_string(census_height) +
                                " has more than 32 pixel pairs (at most 65 pixels)");
  }
  if (paths != 4 && paths != 8) {
    return InvalidArgumentError("sgm paths must be 4 or 8, got " + std::to_string(paths));
  }
  if (raster_paths && paths != 4) {
    return InvalidArgumentError("sgm raster_paths (FPGA mode) uses 4 paths, got paths " +
                                std::to_string(paths));
  }
  if (p2 <= p1) {
    return InvalidArgumentError("sgm p2 (" + std::to_string(p2) + ") must exceed p1 (" +
                                std::to_string(p1) + ")");
  }
  if (census_bits() + 2 * p2 > 255) {
    // Keeps every path cost within 8 bits (see stereo/sgm_kernels.h).
    return InvalidArgumentError("sgm p2 (" + std::to_string(p2) + ") must be at most (255 - " +
                                std::to_string(census_bits()) + " census bits) / 2 = " +
                                std::to_string((255 - census_bits()) / 2));
  }
  return Status::Ok();
}

void SgmOptions::FillP2Table(uint8_t table[256]) const {
  const int a = static_cast<int>(p1), b = static_cast<int>(p2);
  const int s = static_cast<int>(p2_intensity_scale);
  for (int di = 0; di < 256; ++di) {
    table[di] = static_cast<uint8_t>(s > 0 ? std::max(a + 1, b * s / (s + di)) : b);
  }
}

}  // namespace cairn
