#include "io/jpeg_codec.h"

// jpeglib.h needs size_t and FILE declared first.
#include <cstddef>
#include <cstdio>
#include <csetjmp>
#include <cstdlib>

#include <jpeglib.h>

namespace cairn {
namespace {

// libjpeg reports errors through error_exit, which must not return: it jumps back to the frame
// that called setjmp. What must outlive an error lives here, in the caller's frame.
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void OnError(j_common_ptr info) {
  auto* error = reinterpret_cast<JpegError*>(info->err);
  (*info->err->format_message)(info, error->message);
  std::longjmp(error->jump, 1);
}

// Warnings (extraneous bytes, a premature end that libjpeg pads) are not errors for us.
void OnMessage(j_common_ptr) {}

jpeg_error_mgr* InstallErrorHandler(JpegError* error) {
  jpeg_error_mgr* manager = jpeg_std_error(&error->manager);
  manager->error_exit = OnError;
  manager->output_message = OnMessage;
  error->message[0] = '\0';
  return manager;
}

// Returns false after a libjpeg error. EXIF orientation is not applied: a calibrated camera's
// pixels are used as the sensor delivered them.
bool ReadImage(jpeg_decompress_struct* jpeg, JpegError* error, std::span<const uint8_t> bytes, ImageReadMode mode,
               cv::Mat* image) {
  if (setjmp(error->jump)) return false;
  jpeg_mem_src(jpeg, bytes.data(), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(jpeg, TRUE);
  if (jpeg->jpeg_color_space == JCS_CMYK || jpeg->jpeg_color_space == JCS_YCCK) {
    std::snprintf(error->message, sizeof(error->message), "CMYK JPEG images are not supported");
    return false;
  }
  const bool gray = mode != ImageReadMode::kUnchanged || jpeg->jpeg_color_space == JCS_GRAYSCALE;
  jpeg->out_color_space = gray ? JCS_GRAYSCALE : JCS_EXT_BGR;
  jpeg_start_decompress(jpeg);
  const int channels = static_cast<int>(jpeg->output_components);
  if (uint64_t{jpeg->output_width} * jpeg->output_height * static_cast<uint64_t>(channels) > ImageCodec::kMaxPixelBytes) {
    std::snprintf(error->message, sizeof(error->message), "image larger than 1 GiB");
    return false;
  }
  image->create(static_cast<int>(jpeg->output_height), static_cast<int>(jpeg->output_width), CV_8UC(channels));
  while (jpeg->output_scanline < jpeg->output_height) {
    JSAMPROW row = image->ptr<JSAMPLE>(static_cast<int>(jpeg->output_scanline));
    jpeg_read_scanlines(jpeg, &row, 1);
  }
  jpeg_finish_decompress(jpeg);
  return true;
}

bool WriteImage(jpeg_compress_struct* jpeg, JpegError* error, const cv::Mat& image, int quality, ColourOrder order,
                unsigned char** buffer, unsigned long* size) {
  if (setjmp(error->jump)) return false;
  jpeg_mem_dest(jpeg, buffer, size);
  jpeg->image_width = static_cast<JDIMENSION>(image.cols);
  jpeg->image_height = static_cast<JDIMENSION>(image.rows);
  jpeg->input_components = image.channels();
  jpeg->in_color_space =
      image.channels() == 1 ? JCS_GRAYSCALE : order == ColourOrder::kBgr ? JCS_EXT_BGR : JCS_EXT_RGB;
  jpeg_set_defaults(jpeg);
  jpeg_set_quality(jpeg, quality, TRUE);
  jpeg_start_compress(jpeg, TRUE);
  while (jpeg->next_scanline < jpeg->image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(image.ptr<JSAMPLE>(static_cast<int>(jpeg->next_scanline)));
    jpeg_write_scanlines(jpeg, &row, 1);
  }
  jpeg_finish_compress(jpeg);
  return true;
}

}  // namespace

bool JpegCodec::Recognizes(std::span<const uint8_t> bytes) {
  return bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
}

Expected<cv::Mat> JpegCodec::Decode(std::span<const uint8_t> bytes, ImageReadMode mode, const std::string& where) {
  jpeg_decompress_struct jpeg{};
  JpegError error{};
  jpeg.err = InstallErrorHandler(&error);
  jpeg_create_decompress(&jpeg);
  cv::Mat image;
  const bool ok = ReadImage(&jpeg, &error, bytes, mode, &image);
  jpeg_destroy_decompress(&jpeg);
  if (!ok) return DataLossError(where + ": bad JPEG: " + error.message);
  return image;
}

Status JpegCodec::Encode(const cv::Mat& image, int quality, ColourOrder order, std::vector<uint8_t>* out) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    return InvalidArgumentError("JPEG encoding takes 8-bit grey or 3-channel colour images");
  }
  if (quality < 1 || quality > 100) return InvalidArgumentError("JPEG quality " + std::to_string(quality) + " is not in 1-100");
  jpeg_compress_struct jpeg{};
  JpegError error{};
  jpeg.err = InstallErrorHandler(&error);
  jpeg_create_compress(&jpeg);
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  const bool ok = WriteImage(&jpeg, &error, image, quality, order, &buffer, &size);
  jpeg_destroy_compress(&jpeg);
  if (ok) out->assign(buffer, buffer + size);
  std::free(buffer);
  if (!ok) return InternalError(std::string("JPEG encoding failed: ") + error.message);
  return Status::Ok();
}

}  // namespace cairn
