#include "stereo/stereo_image_io.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "io/image_codec.h"

namespace cairn {

Expected<GrayPair> LoadGrayPair(const std::string& left_path, const std::string& right_path) {
  GrayPair pair;
  auto left = ImageCodec::Read(left_path, ImageReadMode::kGray8);
  if (!left.ok()) return left.status();
  auto right = ImageCodec::Read(right_path, ImageReadMode::kGray8);
  if (!right.ok()) return right.status();
  pair.left = std::move(*left);
  pair.right = std::move(*right);
  if (pair.left.size() != pair.right.size()) {
    return InvalidArgumentError("left image " + left_path + " is " +
                                std::to_string(pair.left.cols) + "x" +
                                std::to_string(pair.left.rows) + " but right image " + right_path +
                                " is " + std::to_string(pair.right.cols) + "x" +
                                std::to_string(pair.right.rows));
  }
  return pair;
}

FloatImage DisparityToFloat(const StereoMatcherOutput& output) {
  FloatImage img{output.width, output.height, {}};
  img.data.resize(output.disparity.size());
  for (size_t i = 0; i < output.disparity.size(); ++i) {
    const int16_t d = output.disparity[i];
    img.data[i] = d == kInvalidDisparity ? std::numeric_limits<float>::infinity()
                                         : static_cast<float>(d) / kDisparityScale;
  }
  return img;
}

Status WriteDisparityPng(const std::string& path, const StereoMatcherOutput& output,
                         int min_disparity, int max_disparity) {
  cv::Mat gray(output.height, output.width, CV_8UC1);
  cv::Mat invalid(output.height, output.width, CV_8UC1);
  const double range = std::max(1, max_disparity - min_disparity);
  for (int y = 0; y < output.height; ++y) {
    for (int x = 0; x < output.width; ++x) {
      const int16_t d = output.disparity_at(x, y);
      invalid.at<uint8_t>(y, x) = d == kInvalidDisparity ? 255 : 0;
      const double v = d == kInvalidDisparity
                           ? 0.0
                           : (static_cast<double>(d) / kDisparityScale - min_disparity) / range;
      gray.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(255.0 * v);
    }
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_JET);
  colour.setTo(cv::Scalar(0, 0, 0), invalid);
  return ImageCodec::Write(path, colour);
}

}  // namespace cairn
