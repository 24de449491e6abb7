#pragma once
// OpenCV's StereoSGBM behind the StereoMatcher interface: the baseline our kernel is measured
// against (same disparity range and input), with the settings OpenCV's documentation suggests.

#include <memory>
#include <string>

#include <opencv2/calib3d.hpp>

#include "stereo/stereo_matcher_interface.h"

namespace cairn {

class OpenCvSgbmMatcher final : public StereoMatcher {
 public:
  // mode: cv::StereoSGBM::MODE_SGBM_3WAY, MODE_HH4, MODE_SGBM or MODE_HH.
  OpenCvSgbmMatcher(int min_disparity, int num_disparities, int mode, int block_size = 5);

  std::string_view name() const override { return name_; }
  Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) override;

 private:
  cv::Ptr<cv::StereoSGBM> sgbm_;
  std::string name_;
  cv::Mat disparity_;
};

}  // namespace cairn
