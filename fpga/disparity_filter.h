#pragma once
// Integer post-filters on a fixed-point disparity image (1/16 px, kInvalidDisparity = invalid).
// Shared by every backend, so they are part of the bit-exact contract.

#include <cstdint>
#include <vector>

namespace cairn {

class DisparityFilter {
 public:
  // 3x3 median of the valid pixels around each valid pixel (lower middle for an even count);
  // invalid pixels stay invalid. Rows [y0, y1) of `out` are written; in and out must differ.
  static void Median3x3(const int16_t* in, int16_t* out, int width, int height, int y0, int y1);

  // Invalidates 4-connected regions of fewer than max_size pixels whose neighbours differ by at
  // most max_diff. Buffers are kept between calls (no allocation for a repeated size).
  void RemoveSpeckles(int16_t* disparity, int width, int height, int max_size, int max_diff);

  // Fills each invalid run of a row with the smaller (farther) of its valid end values, or the one
  // valid end at an image border.
  static void FillHolesRow(int16_t* row, int width);

 private:
  std::vector<uint8_t> label_;
  std::vector<int32_t> stack_;
  std::vector<int32_t> region_;
};

}  // namespace cairn
