#pragma once
// Image buffers are shared, immutable once published, and never copied between stages: a driver
// hands out a buffer whose deleter returns the memory to its pool (V4L2/Aravis ring buffers), and
// every consumer holds a reference for as long as it reads.

#include <cstddef>
#include <cstdint>
#include <memory>

namespace cairn {

enum class PixelFormat : uint8_t { kGray8, kRgb8, kBgr8 };

int BytesPerPixel(PixelFormat format);

struct Image {
  std::shared_ptr<const uint8_t[]> data;
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes between rows
  PixelFormat format = PixelFormat::kGray8;

  // A gray view of pixels someone else owns (they must outlive every copy of the view).
  static Image GrayView(const uint8_t* pixels, int width, int height, int stride) {
    Image image;
    image.data = std::shared_ptr<const uint8_t[]>(pixels, [](const uint8_t*) {});
    image.width = width;
    image.height = height;
    image.stride = stride;
    return image;
  }

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  const uint8_t* row(int y) const { return data.get() + static_cast<std::ptrdiff_t>(y) * stride; }
  size_t size_bytes() const { return static_cast<size_t>(stride) * static_cast<size_t>(height); }
};

}  // namespace cairn
