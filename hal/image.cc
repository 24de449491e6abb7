#include "hal/image.h"

namespace cairn {

int BytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8: return 1;
    case PixelFormat::kRgb8:
    case PixelFormat::kBgr8: return 3;
  }
  return 1;
}

}  // namespace cairn
