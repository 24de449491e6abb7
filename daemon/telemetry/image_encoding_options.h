#pragma once
// How camera images are stored in recordings and sent on the live stream: raw (foxglove.RawImage,
// bit exact), or compressed (foxglove.CompressedImage): PNG is lossless, JPEG lossy but about ten
// times smaller, so a long mission fits on the robot's disk and a thin radio link.

#include "common/options_visitor.h"

namespace cairn {

enum class ImageFormat { kRaw, kPng, kJpeg };

struct ImageEncodingOptions {
  ImageFormat format = ImageFormat::kRaw;
  int64_t jpeg_quality = 90;

  void Visit(OptionsVisitor& v) {
    v.Choice("format", format, {{"raw", ImageFormat::kRaw}, {"png", ImageFormat::kPng}, {"jpeg", ImageFormat::kJpeg}});
    v.Integer("jpeg_quality", jpeg_quality, 1, 100, "");
  }
};

}  // namespace cairn
