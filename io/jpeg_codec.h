#pragma once
// JPEG through libjpeg(-turbo), for ImageCodec (which states the pixel conventions).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/status.h"
#include "io/image_codec.h"

namespace cairn {

class JpegCodec {
 public:
  static bool Recognizes(std::span<const uint8_t> bytes);
  static Expected<cv::Mat> Decode(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where);
  static Status Encode(const cv::Mat& image, int quality, ColourOrder order, std::vector<uint8_t>* out);
};

}  // namespace cairn
