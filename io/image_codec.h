#pragma once
// Image files and buffers: PNG (libpng), JPEG (libjpeg-turbo) and binary PGM/PPM, read into and
// written from cv::Mat. cairn does not link OpenCV's imgcodecs: through GDAL and the formats it
// never uses, that library loads about 140 shared libraries, which made every short command slow
// to start and would put all of them on the robots' boards.
//
// Pixels follow OpenCV's conventions so that results match cv::imread: colour is BGR(A), 16-bit
// samples are native-endian, and grey from colour PNG is libpng's 0.299/0.587/0.114 weighting.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/status.h"

namespace cairn {

enum class ImageReadMode {
  kUnchanged,     // the file's channels (grey, BGR or BGRA) and depth (8 or 16 bit)
  kGray8,         // one 8-bit channel: colour converted, 16-bit reduced to its high byte
  kGrayAnyDepth,  // one channel at the file's depth (8 or 16 bit)
};

// The order of a 3- or 4-channel image's colours in memory.
enum class ColourOrder { kBgr, kRgb };

class ImageCodec {
 public:
  // A corrupt header must not make a decoder allocate more than this.
  static constexpr uint64_t kMaxPixelBytes = uint64_t{1} << 30;

  // Decodes PNG, JPEG or binary PGM/PPM (P5/P6), recognised by their first bytes. `where` names
  // the source in errors.
  static Expected<cv::Mat> Decode(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where);
  static Expected<cv::Mat> Read(const std::string& path, ImageReadMode mode);

  // 8-bit grey, 8-bit colour (3 or 4 channels) or 16-bit grey. `level` 0-9 trades speed for size.
  static Status EncodePng(const cv::Mat& image, int level, std::vector<uint8_t>* out,
                          ColourOrder order = ColourOrder::kBgr);
  // 8-bit grey or 3-channel colour; `quality` 1-100.
  static Status EncodeJpeg(const cv::Mat& image, int quality, std::vector<uint8_t>* out,
                           ColourOrder order = ColourOrder::kBgr);

  // By the path's extension: .png (level 1, OpenCV's default), .jpg/.jpeg (quality 95), .pgm/.ppm.
  // A failed write removes what it wrote.
  static Status Write(const std::string& path, const cv::Mat& image);
};

}  // namespace cairn
