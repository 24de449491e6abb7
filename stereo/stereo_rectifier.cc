#include "stereo/stereo_rectifier.h"

#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace cairn {
namespace {

cv::Mat CameraMatrix(const PinholeRadTan& k) {
  return (cv::Mat_<double>(3, 3) << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
}

cv::Mat Distortion(const PinholeRadTan& k) {
  return (cv::Mat_<double>(1, 4) << k.k1, k.k2, k.p1, k.p2);
}

}  // namespace

Expected<StereoRectifier> StereoRectifier::Create(const StereoCalibration& calibration,
                                                  double alpha) {
  const PinholeRadTan& kl = calibration.left.intrinsics;
  const PinholeRadTan& kr = calibration.right.intrinsics;
  if (kl.width < 1 || kl.height < 1 || kl.width != kr.width || kl.height != kr.height) {
    return InvalidArgumentError("stereo calibration: left and right image sizes must be equal and "
                                "positive");
  }
  if (kl.fx <= 0 || kl.fy <= 0 || kr.fx <= 0 || kr.fy <= 0) {
    return InvalidArgumentError("stereo calibration: focal lengths must be positive");
  }
  if (calibration.baseline() <= 0.0) {
    return InvalidArgumentError("stereo calibration: zero baseline");
  }
  // OpenCV wants the transform from left to right camera coordinates: T_right_left.
  const Eigen::Isometry3d T_r_l = calibration.T_left_right().inverse();
  cv::Mat rot(3, 3, CV_64F), trans(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rot.at<double>(r, c) = T_r_l.linear()(r, c);
    trans.at<double>(r) = T_r_l.translation()(r);
  }
  StereoRectifier out;
  out.size_ = cv::Size(kl.width, kl.height);
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(CameraMatrix(kl), Distortion(kl), CameraMatrix(kr), Distortion(kr), out.size_,
                    rot, trans, r1, r2, p1, p2, q, cv::CALIB_ZERO_DISPARITY, alpha, out.size_);
  cv::initUndistortRectifyMap(CameraMatrix(kl), Distortion(kl), r1, p1, out.size_, CV_16SC2,
                              out.left_map_xy_, out.left_map_frac_);
  cv::initUndistortRectifyMap(CameraMatrix(kr), Distortion(kr), r2, p2, out.size_, CV_16SC2,
                              out.right_map_xy_, out.right_map_frac_);
  out.focal_px_ = p1.at<double>(0, 0);
  out.cx_ = p1.at<double>(0, 2);
  out.cy_ = p1.at<double>(1, 2);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.R_left_rect_(r, c) = r1.at<double>(c, r);
  }
  out.baseline_ = calibration.baseline();
  return out;
}

Status StereoRectifier::Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat* left_out,
                                cv::Mat* right_out) const {
  for (const cv::Mat* m : {&left, &right}) {
    if (m->size() != size_ || m->type() != CV_8UC1) {
      return InvalidArgumentError("rectify: expected 8-bit gray " + std::to_string(size_.width) +
                                  "x" + std::to_string(size_.height) + " images, got " +
                                  std::to_string(m->cols) + "x" + std::to_string(m->rows));
    }
  }
  cv::remap(left, *left_out, left_map_xy_, left_map_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(right, *right_out, right_map_xy_, right_map_frac_, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT);
  return Status::Ok();
}

}  // namespace cairn
