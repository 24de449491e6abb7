#pragma once
// Rectification of a calibrated stereo pair: the maps are computed once from the calibration
// (OpenCV stereoRectify, zero skew, common focal length) and stored in OpenCV's fixed-point
// format, so each frame costs one integer bilinear remap per image.

#include <opencv2/core.hpp>

#include "hal/calibration.h"
#include "hal/status.h"

namespace cairn {

class StereoRectifier {
 public:
  // alpha: 0 keeps only valid pixels, 1 keeps every source pixel (OpenCV's meaning).
  static Expected<StereoRectifier> Create(const StereoCalibration& calibration, double alpha = 0.0);

  // Inputs must have the calibrated size and be 8-bit gray; outputs are reused between calls.
  Status Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_out,
                 cv::Mat* right_out) const;

  double focal_px() const { return focal_px_; }
  double baseline() const { return baseline_; }
  cv::Size size() const { return size_; }

 private:
  cv::Size size_;
  cv::Mat left_map_xy_, left_map_frac_, right_map_xy_, right_map_frac_;
  double focal_px_ = 0.0;
  double baseline_ = 0.0;
};

}  // namespace cairn
