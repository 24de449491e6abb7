#include "io/image_codec.h"

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <png.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

cv::Mat Noise(int rows, int cols, int type, uint32_t seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

bool Same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(ImageCodecTest, LosslessFormatsRoundTripEveryPixel) {
  const testing::ScopedTempDir temp("image_codec");
  const std::string dir = temp.path();
  const struct {
    const char* name;
    int type;
  } cases[] = {{"g8.png", CV_8UC1}, {"g16.png", CV_16UC1}, {"bgr.png", CV_8UC3}, {"bgra.png", CV_8UC4},
               {"g8.pgm", CV_8UC1}, {"g16.pgm", CV_16UC1}, {"bgr.ppm", CV_8UC3}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const cv::Mat image = Noise(37, 53, c.type, 7);
    ASSERT_TRUE(ImageCodec::Write(dir + "/" + c.name, image).ok());
    const auto back = ImageCodec::Read(dir + "/" + c.name, ImageReadMode::kUnchanged);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_TRUE(Same(*back, image));
    // OpenCV reads what we write as we do.
    EXPECT_TRUE(Same(cv::imread(dir + "/" + c.name, cv::IMREAD_UNCHANGED), image));
  }
}

TEST(ImageCodecTest, GreyConversionsEqualOpenCvs) {
  const testing::ScopedTempDir temp("image_codec_grey");
  const std::string dir = temp.path();
  const cv::Mat colour = Noise(41, 29, CV_8UC3, 3);
  const cv::Mat wide = Noise(41, 29, CV_16UC1, 4);
  const cv::Mat wide_colour = Noise(41, 29, CV_16UC3, 5);
  ASSERT_TRUE(cv::imwrite(dir + "/c.png", colour));
  ASSERT_TRUE(cv::imwrite(dir + "/c.ppm", colour));
  ASSERT_TRUE(cv::imwrite(dir + "/c.jpg", colour));
  ASSERT_TRUE(cv::imwrite(dir + "/w.png", wide));
  ASSERT_TRUE(cv::imwrite(dir + "/wc.png", wide_colour));
  for (const char* name : {"c.png", "c.ppm", "c.jpg", "w.png", "wc.png"}) {
    SCOPED_TRACE(name);
    const std::string path = dir + "/" + name;
    EXPECT_TRUE(Same(*ImageCodec::Read(path, ImageReadMode::kGray8), cv::imread(path, cv::IMREAD_GRAYSCALE)));
    EXPECT_TRUE(Same(*ImageCodec::Read(path, ImageReadMode::kGrayAnyDepth),
                     cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH)));
    EXPECT_TRUE(Same(*ImageCodec::Read(path, ImageReadMode::kUnchanged), cv::imread(path, cv::IMREAD_UNCHANGED)));
  }
}

// Every image of the shared data decodes to OpenCV's pixels in each mode the tools use.
TEST(ImageCodecTest, SharedDataImagesDecodeAsOpenCvDecodesThem) {
  const std::string data = testing::DataDir();
  CAIRN_REQUIRE_PATH(data);
  std::vector<std::string> paths;
  for (const auto& entry : fs::recursive_directory_iterator(data)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".png" || ext == ".jpg") paths.push_back(entry.path().string());
  }
  // Sorted so the sample does not depend on directory order or on where the data lives.
  std::sort(paths.begin(), paths.end());
  int files = 0;
  int sequence_images = 0;
  for (const std::string& path : paths) {
    // One image in eight of the long EuRoC sequences is plenty; the data directory's own path
    // (often ending in /data) must not count.
    const bool in_sequence = fs::relative(path, data).string().find("/data/") != std::string::npos;
    if (in_sequence && sequence_images++ % 8 != 0) continue;
    SCOPED_TRACE(path);
    ++files;
    const auto grey = ImageCodec::Read(path, ImageReadMode::kGray8);
    ASSERT_TRUE(grey.ok()) << grey.status().message();
    EXPECT_TRUE(Same(*grey, cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION)));
    EXPECT_TRUE(Same(*ImageCodec::Read(path, ImageReadMode::kGrayAnyDepth),
                     cv::imread(path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH | cv::IMREAD_IGNORE_ORIENTATION)));
    EXPECT_TRUE(Same(*ImageCodec::Read(path, ImageReadMode::kUnchanged), cv::imread(path, cv::IMREAD_UNCHANGED)));
  }
  // 18 stand-alone images and one in eight of 190 sequence images.
  EXPECT_GE(files, 40);
}

// libpng writes an Adam7-interlaced grey image of `image` (8-bit) to `path`.
bool WriteInterlacedPng(const std::string& path, const cv::Mat& image) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  std::vector<png_bytep> rows(static_cast<size_t>(image.rows));
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows), 8,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_ADAM7, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_interlace_handling(png);
  for (int y = 0; y < image.rows; ++y) rows[static_cast<size_t>(y)] = const_cast<png_bytep>(image.ptr<png_byte>(y));
  png_write_image(png, rows.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return std::fclose(f) == 0;
}

TEST(ImageCodecTest, InterlacedPngDecodesWhole) {
  const testing::ScopedTempDir temp("image_codec_adam7");
  const std::string path = temp.path() + "/adam7.png";
  const cv::Mat image = Noise(29, 37, CV_8UC1, 11);
  ASSERT_TRUE(WriteInterlacedPng(path, image));
  const auto back = ImageCodec::Read(path, ImageReadMode::kGray8);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_TRUE(Same(*back, image));
  EXPECT_TRUE(Same(cv::imread(path, cv::IMREAD_GRAYSCALE), image));
}

TEST(ImageCodecTest, JpegKeepsTheImageCloseAndTheChannelOrder) {
  cv::Mat bgr(64, 64, CV_8UC3, cv::Scalar(200, 100, 30));  // blue-ish in BGR
  std::vector<uint8_t> bytes;
  ASSERT_TRUE(ImageCodec::EncodeJpeg(bgr, 95, &bytes).ok());
  const auto as_bgr = ImageCodec::Decode(bytes, ImageReadMode::kUnchanged, "mem");
  ASSERT_TRUE(as_bgr.ok());
  EXPECT_LE(cv::norm(*as_bgr, bgr, cv::NORM_INF), 3.0);
  // The same bytes read as RGB: the encoder is told the order instead of converting a copy.
  ASSERT_TRUE(ImageCodec::EncodeJpeg(bgr, 95, &bytes, ColourOrder::kRgb).ok());
  const auto swapped = ImageCodec::Decode(bytes, ImageReadMode::kUnchanged, "mem");
  ASSERT_TRUE(swapped.ok());
  EXPECT_NEAR(swapped->at<cv::Vec3b>(10, 10)[0], 30, 3);
  EXPECT_NEAR(swapped->at<cv::Vec3b>(10, 10)[2], 200, 3);
  const cv::Mat grey = Noise(48, 80, CV_8UC1, 9);
  ASSERT_TRUE(ImageCodec::EncodeJpeg(grey, 100, &bytes).ok());
  const auto back = ImageCodec::Decode(bytes, ImageReadMode::kUnchanged, "mem");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->type(), CV_8UC1);
  EXPECT_LE(cv::norm(*back, grey, cv::NORM_L1) / static_cast<double>(grey.total()), 2.0);
}

TEST(ImageCodecTest, DamagedBytesGiveAnErrorNamingTheSource) {
  const cv::Mat image = Noise(30, 30, CV_8UC1, 1);
  std::vector<uint8_t> png;
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(ImageCodec::EncodePng(image, 6, &png).ok());
  ASSERT_TRUE(ImageCodec::EncodeJpeg(image, 90, &jpeg).ok());
  std::mt19937 rng(5);
  for (const std::vector<uint8_t>* original : {&png, &jpeg}) {
    // Truncated anywhere: an error, never a crash.
    for (size_t n : {size_t{0}, size_t{3}, size_t{20}, original->size() / 2, original->size() - 1}) {
      const std::vector<uint8_t> cut(original->begin(), original->begin() + static_cast<ptrdiff_t>(n));
      const auto r = ImageCodec::Decode(cut, ImageReadMode::kGray8, "camera/left");
      if (!r.ok()) {
        EXPECT_NE(r.status().message().find("camera/left"), std::string::npos) << r.status().message();
      }
    }
    // Flipped bytes: decoded or refused, with no sanitizer finding.
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<uint8_t> bad = *original;
      bad[rng() % bad.size()] ^= static_cast<uint8_t>(1 + rng() % 255);
      (void)ImageCodec::Decode(bad, ImageReadMode::kUnchanged, "x");
    }
  }
  const std::vector<uint8_t> png_cut(png.begin(), png.begin() + static_cast<ptrdiff_t>(png.size() / 2));
  EXPECT_FALSE(ImageCodec::Decode(png_cut, ImageReadMode::kGray8, "x").ok());
  const std::string huge = "P5\n100000 100000\n255\n";
  const auto r = ImageCodec::Decode({reinterpret_cast<const uint8_t*>(huge.data()), huge.size()}, ImageReadMode::kGray8, "big.pgm");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("big.pgm"), std::string::npos);
  const std::string text = "hello, not an image";
  EXPECT_FALSE(ImageCodec::Decode({reinterpret_cast<const uint8_t*>(text.data()), text.size()}, ImageReadMode::kGray8, "t").ok());
  EXPECT_EQ(ImageCodec::Read("/nonexistent/x.png", ImageReadMode::kGray8).status().code(), StatusCode::kNotFound);
  const testing::ScopedTempDir temp("image_codec_bad");
  EXPECT_FALSE(ImageCodec::Write(temp.path() + "/x.tif", image).ok());
  EXPECT_FALSE(ImageCodec::EncodeJpeg(cv::Mat(4, 4, CV_16UC1), 90, &jpeg).ok());
}

}  // namespace
}  // namespace cairn
