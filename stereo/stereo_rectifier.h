#pragma once
// Rectification of a calibrated stereo pair: the maps are computed once from the calibration
// (OpenCV stereoRectify, zero skew, common focal length) and stored in OpenCV's fixed-point
// format, so each frame costs one integer bilinear remap per image.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "common/status.h"
#include "hal/calibration.h"

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
  // Principal point of both rectified images (px).
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  // Orientation of the rectified left camera in the original left camera frame (R1^T in
  // OpenCV's terms): T_body_rect = T_body_cam * [R_left_rect | 0].
  const Eigen::Matrix3d& R_left_rect() const { return R_left_rect_; }
  cv::Size size() const { return size_; }

 private:
  cv::Size size_;
  cv::Mat left_map_xy_, left_map_frac_, right_map_xy_, right_map_frac_;
  double focal_px_ = 0.0;
  double baseline_ = 0.0;
  double cx_ = 0.0, cy_ = 0.0;
  Eigen::Matrix3d R_left_rect_ = Eigen::Matrix3d::Identity();
};

}  // namespace cairn
