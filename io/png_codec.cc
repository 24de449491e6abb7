#include "io/png_codec.h"

#include <png.h>

#include <cstdio>
#include <cstring>

namespace cairn {
namespace {

constexpr bool kLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

// libpng reports errors by longjmp: everything a reader or writer must keep past an error lives
// here, in the caller's frame, never in the frame that calls setjmp.
struct PngState {
  std::span<const uint8_t> in;
  size_t offset = 0;
  std::vector<uint8_t>* out = nullptr;
  char error[256] = "";
};

void OnError(png_structp png, png_const_charp message) {
  auto* state = static_cast<PngState*>(png_get_error_ptr(png));
  std::snprintf(state->error, sizeof(state->error), "%s", message);
  png_longjmp(png, 1);
}

// Warnings (an unusual colour profile, a bad optional chunk) do not stop reading.
void OnWarning(png_structp, png_const_charp) {}

void ReadBytes(png_structp png, png_bytep data, size_t n) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  if (n > state->in.size() - state->offset) png_error(png, "data ends early");
  std::memcpy(data, state->in.data() + state->offset, n);
  state->offset += n;
}

void WriteBytes(png_structp png, png_bytep data, size_t n) {
  auto* state = static_cast<PngState*>(png_get_io_ptr(png));
  state->out->insert(state->out->end(), data, data + n);
}

void Flush(png_structp) {}

// Returns false after a libpng error (its message is in the state). The transforms are those
// that make the result equal cv::imread's.
bool ReadImage(png_structp png, png_infop info, ImageReadMode mode, cv::Mat* image, std::vector<png_bytep>* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int depth = 0;
  int colour = 0;
  png_get_IHDR(png, info, &width, &height, &depth, &colour, nullptr, nullptr, nullptr);
  const bool gray = mode != ImageReadMode::kUnchanged;
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS) != 0) {
    if (gray) {
      // Transparency is dropped below with the alpha channel; expanding it first is wasted work.
    } else {
      png_set_tRNS_to_alpha(png);
    }
  }
  if (depth == 16) {
    if (mode == ImageReadMode::kGray8) {
      png_set_strip_16(png);
    } else if (kLittleEndian) {
      png_set_swap(png);
    }
  }
  if (gray) {
    if ((colour & PNG_COLOR_MASK_COLOR) != 0) png_set_rgb_to_gray(png, 1, 0.299, 0.587);
    if ((colour & PNG_COLOR_MASK_ALPHA) != 0) png_set_strip_alpha(png);
  } else {
    if ((colour & PNG_COLOR_MASK_COLOR) != 0 || colour == PNG_COLOR_TYPE_PALETTE) png_set_bgr(png);
    if (colour == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);  // BGRA, as OpenCV gives
  }
  png_set_interlace_handling(png);  // Adam7 files: png_read_image merges the passes
  png_read_update_info(png, info);
  const int channels = png_get_channels(png, info);
  const int out_depth = png_get_bit_depth(png, info);
  if (channels < 1 || channels > 4 || (out_depth != 8 && out_depth != 16)) png_error(png, "unexpected pixel layout");
  if (uint64_t{width} * height * static_cast<uint64_t>(channels) * (out_depth / 8) > ImageCodec::kMaxPixelBytes) {
    png_error(png, "image larger than 1 GiB");
  }
  image->create(static_cast<int>(height), static_cast<int>(width), CV_MAKETYPE(out_depth == 16 ? CV_16U : CV_8U, channels));
  rows->resize(height);
  for (png_uint_32 y = 0; y < height; ++y) (*rows)[y] = image->ptr<png_byte>(static_cast<int>(y));
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  return true;
}

bool WriteImage(png_structp png, png_infop info, const cv::Mat& image, int level, ColourOrder order) {
  if (setjmp(png_jmpbuf(png))) return false;
  const int channels = image.channels();
  const int colour = channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
  png_set_compression_level(png, level);
  // The fastest settings (as OpenCV's default): sub filter only, for the recorder and telemetry.
  if (level <= 1) png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows),
               image.depth() == CV_16U ? 16 : 8, colour, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (channels >= 3 && order == ColourOrder::kBgr) png_set_bgr(png);
  if (image.depth() == CV_16U && kLittleEndian) png_set_swap(png);
  for (int y = 0; y < image.rows; ++y) png_write_row(png, image.ptr<png_byte>(y));
  png_write_end(png, info);
  return true;
}

}  // namespace

bool PngCodec::Recognizes(std::span<const uint8_t> bytes) {
  return bytes.size() >= 8 && png_sig_cmp(bytes.data(), 0, 8) == 0;
}

Expected<cv::Mat> PngCodec::Decode(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where) {
  PngState state;
  state.in = bytes;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &state, OnError, OnWarning);
  png_infop info = png == nullptr ? nullptr : png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return InternalError(where + ": cannot start the PNG decoder");
  }
  png_set_read_fn(png, &state, ReadBytes);
  cv::Mat image;
  std::vector<png_bytep> rows;
  const bool ok = ReadImage(png, info, mode, &image, &rows);
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) return DataLossError(where + ": bad PNG: " + state.error);
  return image;
}

Status PngCodec::Encode(const cv::Mat& image, int level, ColourOrder order, std::vector<uint8_t>* out) {
  const int channels = image.channels();
  const bool depth_ok = image.depth() == CV_8U || (image.depth() == CV_16U && channels == 1);
  if (image.empty() || !depth_ok || (channels != 1 && channels != 3 && channels != 4)) {
    return InvalidArgumentError("PNG encoding takes 8-bit grey or colour, or 16-bit grey, images");
  }
  if (level < 0 || level > 9) return InvalidArgumentError("PNG compression level " + std::to_string(level) + " is not in 0-9");
  PngState state;
  state.out = out;
  out->clear();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, OnError, OnWarning);
  png_infop info = png == nullptr ? nullptr : png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return InternalError("cannot start the PNG encoder");
  }
  png_set_write_fn(png, &state, WriteBytes, Flush);
  const bool ok = WriteImage(png, info, image, level, order);
  png_destroy_write_struct(&png, &info);
  if (!ok) return InternalError(std::string("PNG encoding failed: ") + state.error);
  return Status::Ok();
}

}  // namespace cairn
