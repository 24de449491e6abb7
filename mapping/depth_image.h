#pragma once
// One rectified depth image as mapping consumes it, and the 3-D points made from it.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "common/status.h"
#include "common/timestamp.h"
#include "hal/calibration.h"
#include "mapping/line_sighting.h"

namespace cairn {

// Depth along the optical axis of the rectified left camera, row-major. NaN: no measurement;
// +inf: beyond stereo range (disparity 0), which negative-edge detection and free-space clearing
// still use.
struct DepthImage {
  Timestamp time;
  int width = 0;
  int height = 0;
  std::vector<float> depth;
  std::vector<uint8_t> intensity;  // optional gray values of the left image (empty: none)
  std::vector<LineSighting> lines;  // optional straight edges seen in it, camera frame

  float at(int u, int v) const { return depth[static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u)]; }
  // Checks sizes and values (no negative depths); names what is wrong.
  Status Validate() const;
  // From the stereo matchers' fixed-point disparity (int16, 1/16 px, INT16_MIN invalid; see
  // fpga/README.md): depth = f b / (d + offset); d = 0 is +inf.
  static Expected<DepthImage> FromDisparity(std::span<const int16_t> disparity, int width, int height,
                                            double focal_px, double baseline,
                                            double disparity_offset_px = 0.0);
  // The same into this image, whose buffers keep their capacity: no allocation once an image of
  // the size has been held. The time, intensity and lines are left as they were.
  Status AssignDisparity(std::span<const int16_t> disparity, int width, int height, double focal_px,
                         double baseline, double disparity_offset_px = 0.0);
};

// The rectified left camera of a stereo pair and where it sits on the body.
struct StereoCamera {
  PinholeRadTan intrinsics;  // rectified: distortion is ignored
  double baseline = 0.0;     // m
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();

  static StereoCamera FromCalibration(const StereoCalibration& c) {
    return {c.left.intrinsics, c.baseline(), c.left.T_body_cam};
  }
};

// Points of one depth image within the error limit, in structure-of-arrays form. Buffers keep
// their capacity between images.
struct CameraPoints {
  Timestamp time;
  Eigen::Isometry3d T_local_cam = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> p_cam;
  std::vector<Eigen::Vector3f> p_local;
  std::vector<float> depth_error;     // eq. 5.2c, m
  std::vector<uint32_t> pixel;        // v * width + u
  std::vector<uint8_t> intensity;     // 0 when the image has none
  std::vector<uint8_t> obstacle;      // set by ObstacleClassifier (0/1)
  // Ends of rays that saw nothing within range (local frame, at the range limit): free space only.
  std::vector<Eigen::Vector3f> far_local;

  size_t size() const { return p_cam.size(); }
  // The first n points (every per-point array; `obstacle` too once it is filled).
  void Truncate(size_t n) {
    p_cam.resize(n);
    p_local.resize(n);
    depth_error.resize(n);
    pixel.resize(n);
    intensity.resize(n);
    if (!obstacle.empty()) obstacle.resize(n);
  }
  // Point `from` into slot `to` (compaction in place).
  void MovePoint(size_t from, size_t to) {
    p_cam[to] = p_cam[from];
    p_local[to] = p_local[from];
    depth_error[to] = depth_error[from];
    pixel[to] = pixel[from];
    intensity[to] = intensity[from];
    if (!obstacle.empty()) obstacle[to] = obstacle[from];
  }
  void Clear() {
    p_cam.clear();
    p_local.clear();
    depth_error.clear();
    pixel.clear();
    intensity.clear();
    obstacle.clear();
    far_local.clear();
  }
};

}  // namespace cairn
