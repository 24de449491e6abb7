#pragma once
// Test helper: a tag36h11 tag drawn into a gray image at a known pose, by a homography of its
// bitmap (libapriltag's own), over a gray background, with a little optical blur.

#include <cstdlib>
#include <memory>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "hal/calibration.h"
#include "hal/image.h"

namespace cairn::testing {

// Draws the tag into `image` (8-bit gray, camera.width x camera.height). The tag's black border
// spans 8 of the bitmap's 10 cells (the outer white cells are drawn too); the frame is AprilTag's
// (x right, y down as printed, z into the tag).
// `family` (default tag36h11) is the code family drawn; its black border must span 8 of 10 cells.
inline void DrawTag(cv::Mat& image, int id, double tag_size, const Eigen::Isometry3d& T_cam_tag,
                    const PinholeRadTan& camera, double blur_sigma = 0.6, apriltag_family_t* other_family = nullptr) {
  apriltag_family_t* family = other_family != nullptr ? other_family : tag36h11_create();
  image_u8_t* bits = apriltag_to_image(family, id);
  constexpr int kUp = 8;  // bitmap pixels per cell
  cv::Mat bitmap(bits->height * kUp, bits->width * kUp, CV_8UC1);
  for (int v = 0; v < bitmap.rows; ++v)
    for (int u = 0; u < bitmap.cols; ++u) bitmap.at<uint8_t>(v, u) = bits->buf[(v / kUp) * bits->stride + u / kUp];
  const double cells = bits->width;  // 10 for tag36h11
  // image_u8_destroy is not exported by Debian's libapriltag; it frees these two blocks.
  std::free(bits->buf);
  std::free(bits);
  if (other_family == nullptr) tag36h11_destroy(family);
  const double cell = tag_size / (cells - 2.0);
  // Bitmap pixel centre -> tag plane (metres).
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  A(0, 0) = A(1, 1) = cell / kUp;
  A(0, 2) = A(1, 2) = (0.5 / kUp - 0.5 * cells) * cell;
  Eigen::Matrix3d P;
  P.col(0) = T_cam_tag.linear().col(0);
  P.col(1) = T_cam_tag.linear().col(1);
  P.col(2) = T_cam_tag.translation();
  Eigen::Matrix3d K;
  K << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d H = K * P * A;
  cv::Matx33d Hcv;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hcv(r, c) = H(r, c);
  const cv::Size size(camera.width, camera.height);
  cv::Mat tag, mask;
  cv::warpPerspective(bitmap, tag, Hcv, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpPerspective(cv::Mat(bitmap.size(), CV_8UC1, cv::Scalar(255)), mask, Hcv, size, cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat blended;
  image.convertTo(blended, CV_32F);
  cv::Mat t32, m32;
  tag.convertTo(t32, CV_32F);
  mask.convertTo(m32, CV_32F, 1.0 / 255.0);
  blended = blended.mul(1.0 - m32) + t32.mul(m32);
  if (blur_sigma > 0.0) cv::GaussianBlur(blended, blended, cv::Size(0, 0), blur_sigma);
  blended.convertTo(image, CV_8U);
}

// A tag drawn over a plain gray background.
inline cv::Mat RenderTag(int id, double tag_size, const Eigen::Isometry3d& T_cam_tag, const PinholeRadTan& camera,
                         double blur_sigma = 0.6) {
  cv::Mat image(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  DrawTag(image, id, tag_size, T_cam_tag, camera, blur_sigma);
  return image;
}

// A view of a continuous 8-bit cv::Mat as an Image (the Mat must outlive it).
inline Image ImageOf(const cv::Mat& m) {
  return Image::GrayView(m.data, m.cols, m.rows, static_cast<int>(m.step[0]));
}

}  // namespace cairn::testing
