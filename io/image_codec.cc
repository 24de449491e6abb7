#include "io/image_codec.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "io/jpeg_codec.h"
#include "io/png_codec.h"

namespace cairn {
namespace {

std::string Extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool IsPnm(std::span<const uint8_t> bytes) {
  return bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == '5' || bytes[1] == '6');
}

// One number of a PNM header, after whitespace and '#' comments; -1 when there is none.
int64_t PnmNumber(std::span<const uint8_t> bytes, size_t* at) {
  while (*at < bytes.size()) {
    if (bytes[*at] == '#') {
      while (*at < bytes.size() && bytes[*at] != '\n') ++*at;
    } else if (std::isspace(bytes[*at]) != 0) {
      ++*at;
    } else {
      break;
    }
  }
  int64_t value = -1;
  while (*at < bytes.size() && std::isdigit(bytes[*at]) != 0 && value < (int64_t{1} << 40)) {
    value = (value < 0 ? 0 : value * 10) + (bytes[*at] - '0');
    ++*at;
  }
  return value;
}

// OpenCV's grey from colour (0.299 R + 0.587 G + 0.114 B in 14-bit fixed point, rounded).
template <typename T>
T GrayOf(T b, T g, T r) {
  return static_cast<T>((uint32_t{b} * 1868u + uint32_t{g} * 9617u + uint32_t{r} * 4899u + (1u << 13)) >> 14);
}

template <typename T>
void ConvertPnmRow(const uint8_t* in, int width, bool colour, bool to_gray, T* out) {
  const int samples = colour ? 3 : 1;
  auto sample = [&](int i) -> T {
    if constexpr (sizeof(T) == 2) return static_cast<T>((in[2 * i] << 8) | in[2 * i + 1]);  // big-endian
    return in[i];
  };
  for (int x = 0; x < width; ++x) {
    if (!colour) {
      out[x] = sample(x);
    } else if (to_gray) {
      out[x] = GrayOf<T>(sample(samples * x + 2), sample(samples * x + 1), sample(samples * x));
    } else {
      out[3 * x] = sample(3 * x + 2);  // RGB in the file, BGR in memory
      out[3 * x + 1] = sample(3 * x + 1);
      out[3 * x + 2] = sample(3 * x);
    }
  }
}

Expected<cv::Mat> DecodePnm(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where) {
  const bool colour = bytes[1] == '6';
  size_t at = 2;
  const int64_t width = PnmNumber(bytes, &at);
  const int64_t height = PnmNumber(bytes, &at);
  const int64_t maxval = PnmNumber(bytes, &at);
  if (width <= 0 || height <= 0 || maxval <= 0 || maxval > 65535 || at >= bytes.size() ||
      std::isspace(bytes[at]) == 0) {
    return DataLossError(where + ": bad PGM/PPM header");
  }
  ++at;  // the single whitespace before the pixels
  const int sample_bytes = maxval > 255 ? 2 : 1;
  const uint64_t row_bytes = static_cast<uint64_t>(width) * (colour ? 3 : 1) * sample_bytes;
  if (row_bytes * static_cast<uint64_t>(height) > ImageCodec::kMaxPixelBytes) return DataLossError(where + ": image larger than 1 GiB");
  if (bytes.size() - at < row_bytes * static_cast<uint64_t>(height)) {
    return DataLossError(where + ": PGM/PPM pixels end early (" + std::to_string(bytes.size() - at) + " of " +
                         std::to_string(row_bytes * static_cast<uint64_t>(height)) + " bytes)");
  }
  const bool to_gray = mode != ImageReadMode::kUnchanged;
  const bool wide = sample_bytes == 2 && mode != ImageReadMode::kGray8;
  const int channels = colour && !to_gray ? 3 : 1;
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_MAKETYPE(wide ? CV_16U : CV_8U, channels));
  std::vector<uint16_t> row16;
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* in = bytes.data() + at + static_cast<size_t>(y) * row_bytes;
    if (wide) {
      ConvertPnmRow<uint16_t>(in, image.cols, colour, to_gray, image.ptr<uint16_t>(y));
    } else if (sample_bytes == 1) {
      ConvertPnmRow<uint8_t>(in, image.cols, colour, to_gray, image.ptr<uint8_t>(y));
    } else {
      // 16-bit samples read as 8-bit keep their high byte, as 16-bit PNG does.
      row16.resize(static_cast<size_t>(image.cols));
      ConvertPnmRow<uint16_t>(in, image.cols, colour, true, row16.data());
      for (int x = 0; x < image.cols; ++x) image.ptr<uint8_t>(y)[x] = static_cast<uint8_t>(row16[static_cast<size_t>(x)] >> 8);
    }
  }
  return image;
}

Status EncodePnm(const cv::Mat& image, std::vector<uint8_t>* out) {
  const bool colour = image.channels() == 3;
  if (image.empty() || !(image.channels() == 1 || (colour && image.depth() == CV_8U)) ||
      (image.depth() != CV_8U && image.depth() != CV_16U)) {
    return InvalidArgumentError("PGM/PPM encoding takes 8- or 16-bit grey or 8-bit colour images");
  }
  const bool wide = image.depth() == CV_16U;
  const std::string header = std::string(colour ? "P6\n" : "P5\n") + std::to_string(image.cols) + " " +
                             std::to_string(image.rows) + "\n" + (wide ? "65535\n" : "255\n");
  out->assign(header.begin(), header.end());
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      if (wide) {
        const uint16_t v = image.ptr<uint16_t>(y)[x];
        out->push_back(static_cast<uint8_t>(v >> 8));
        out->push_back(static_cast<uint8_t>(v & 0xFF));
      } else if (colour) {
        const uint8_t* p = image.ptr<uint8_t>(y) + 3 * x;
        out->insert(out->end(), {p[2], p[1], p[0]});
      } else {
        out->push_back(image.ptr<uint8_t>(y)[x]);
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Expected<cv::Mat> ImageCodec::Decode(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where) {
  if (PngCodec::Recognizes(bytes)) return PngCodec::Decode(bytes, mode, where);
  if (JpegCodec::Recognizes(bytes)) return JpegCodec::Decode(bytes, mode, where);
  if (IsPnm(bytes)) return DecodePnm(bytes, mode, where);
  return DataLossError(where + ": not a PNG, JPEG or binary PGM/PPM image");
}

Expected<cv::Mat> ImageCodec::Read(const std::string& path, ImageReadMode mode) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return std::filesystem::exists(path) ? IoError("cannot open image " + path) : NotFoundError("no such image file " + path);
  }
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return IoError("reading image " + path + " failed");
  return Decode(bytes, mode, path);
}

Status ImageCodec::EncodePng(const cv::Mat& image, int level, std::vector<uint8_t>* out, ColourOrder order) {
  return PngCodec::Encode(image, level, order, out);
}

Status ImageCodec::EncodeJpeg(const cv::Mat& image, int quality, std::vector<uint8_t>* out, ColourOrder order) {
  return JpegCodec::Encode(image, quality, order, out);
}

Status ImageCodec::Write(const std::string& path, const cv::Mat& image) {
  const std::string ext = Extension(path);
  std::vector<uint8_t> bytes;
  Status encoded;
  if (ext == ".png") {
    encoded = EncodePng(image, 1, &bytes);
  } else if (ext == ".jpg" || ext == ".jpeg") {
    encoded = EncodeJpeg(image, 95, &bytes);
  } else if (ext == ".pgm" || ext == ".ppm") {
    if ((ext == ".ppm") != (image.channels() == 3)) return InvalidArgumentError(path + ": .pgm takes grey, .ppm colour images");
    encoded = EncodePnm(image, &bytes);
  } else {
    return InvalidArgumentError(path + ": unknown image extension '" + ext + "' (.png, .jpg, .pgm or .ppm)");
  }
  if (!encoded.ok()) return InvalidArgumentError(path + ": " + encoded.message());
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return IoError("cannot create image " + path);
  const bool written = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const bool closed = std::fclose(f) == 0;
  if (!written || !closed) {
    std::remove(path.c_str());
    return IoError("writing image " + path + " failed");
  }
  return Status::Ok();
}

}  // namespace cairn
