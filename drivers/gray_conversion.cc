#include "drivers/gray_conversion.h"

namespace cairn {

void Mono16ToGray8(const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst) {
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = src + static_cast<size_t>(y) * src_stride;
    uint8_t* out = dst + static_cast<size_t>(y) * static_cast<size_t>(width);
    for (int x = 0; x < width; ++x) out[x] = in[2 * x + 1];
  }
}

void Bayer8ToGray8(const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst) {
  if (width < 2 || height < 2) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        dst[y * width + x] = src[static_cast<size_t>(y) * src_stride + static_cast<size_t>(x)];
    return;
  }
  for (int y = 0; y < height; ++y) {
    const int y1 = y + 1 < height ? y + 1 : y - 1;
    const uint8_t* a = src + static_cast<size_t>(y) * src_stride;
    const uint8_t* b = src + static_cast<size_t>(y1) * src_stride;
    uint8_t* out = dst + static_cast<size_t>(y) * static_cast<size_t>(width);
    for (int x = 0; x < width; ++x) {
      const int x1 = x + 1 < width ? x + 1 : x - 1;
      out[x] = static_cast<uint8_t>((a[x] + a[x1] + b[x] + b[x1] + 2) / 4);
    }
  }
}

}  // namespace cairn
