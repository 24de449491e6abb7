#include "stereo/opencv_sgbm_matcher.h"

#include <cmath>
#include <limits>

namespace cairn {

OpenCvSgbmMatcher::OpenCvSgbmMatcher(int min_disparity, int num_disparities, int mode,
                                     int block_size) {
  const int area = block_size * block_size;
  sgbm_ = cv::StereoSGBM::create(min_disparity, num_disparities, block_size, 8 * area, 32 * area,
                                 /*disp12MaxDiff=*/1, /*preFilterCap=*/63,
                                 /*uniquenessRatio=*/10, /*speckleWindowSize=*/100,
                                 /*speckleRange=*/2, mode);
  switch (mode) {
    case cv::StereoSGBM::MODE_SGBM_3WAY: name_ = "opencv-sgbm-3way"; break;
    case cv::StereoSGBM::MODE_HH4: name_ = "opencv-hh4"; break;
    case cv::StereoSGBM::MODE_HH: name_ = "opencv-hh"; break;
    default: name_ = "opencv-sgbm"; break;
  }
}

Status OpenCvSgbmMatcher::Match(const StereoMatcherInput& input, StereoMatcherOutput* output) {
  if (output == nullptr || input.left == nullptr || input.right == nullptr || input.width < 1 ||
      input.height < 1 || input.stride < input.width) {
    return InvalidArgumentError("OpenCvSgbmMatcher::Match: bad input images");
  }
  const cv::Mat l(input.height, input.width, CV_8UC1, const_cast<uint8_t*>(input.left),
                  static_cast<size_t>(input.stride));
  const cv::Mat r(input.height, input.width, CV_8UC1, const_cast<uint8_t*>(input.right),
                  static_cast<size_t>(input.stride));
  sgbm_->compute(l, r, disparity_);
  const size_t n = static_cast<size_t>(input.width) * input.height;
  output->width = input.width;
  output->height = input.height;
  output->disparity.resize(n);
  output->depth.resize(n);
  output->depth_sigma.resize(n);
  // OpenCV marks invalid pixels with (min_disparity - 1) * 16.
  const int invalid_below = sgbm_->getMinDisparity() * 16;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < input.height; ++y) {
    const int16_t* row = disparity_.ptr<int16_t>(y);
    for (int x = 0; x < input.width; ++x) {
      const size_t i = static_cast<size_t>(y) * input.width + x;
      output->disparity[i] = row[x] < invalid_below ? kInvalidDisparity : row[x];
      const double d = row[x] / 16.0 + input.disparity_offset_px;
      const bool ok = output->disparity[i] != kInvalidDisparity && d > 0.0 &&
                      input.focal_px > 0.0 && input.baseline_m > 0.0;
      output->depth[i] = ok ? static_cast<float>(input.focal_px * input.baseline_m / d) : nan;
      output->depth_sigma[i] = nan;
    }
  }
  return Status::Ok();
}

}  // namespace cairn
