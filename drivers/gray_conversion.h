#pragma once
// Conversions of camera pixel formats to the gray8 images the pipeline reads.

#include <cstddef>
#include <cstdint>

namespace cairn {

// Little-endian 16-bit gray (GigE Vision's Mono16) to its upper 8 bits.
void Mono16ToGray8(const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst);

// A Bayer mosaic (any of RG, BG, GB, GR) to gray: the mean of the 2x2 window whose top left is
// the pixel. Every such window holds one red, two green and one blue site whatever the pattern,
// so the gray is (R + 2G + B) / 4 at full resolution, shifted by half a pixel (the calibration of
// the gray images absorbs the shift). The last row and column take the window reaching back.
void Bayer8ToGray8(const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst);

}  // namespace cairn
