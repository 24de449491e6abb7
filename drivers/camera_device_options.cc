#include "drivers/camera_device_options.h"

#include "drivers/xyz_rpy_pose.h"

namespace cairn {

CameraCalibration CameraIntrinsicsOptions::Calibration(const std::string& name) const {
  CameraCalibration c;
  c.name = name;
  c.intrinsics.width = static_cast<int>(width);
  c.intrinsics.height = static_cast<int>(height);
  c.intrinsics.fx = fx;
  c.intrinsics.fy = fy;
  c.intrinsics.cx = cx;
  c.intrinsics.cy = cy;
  c.intrinsics.k1 = k1;
  c.intrinsics.k2 = k2;
  c.intrinsics.p1 = p1;
  c.intrinsics.p2 = p2;
  c.T_body_cam = PoseFromXyzRpy(T_body_cam);
  return c;
}

StereoCalibration CameraDeviceOptions::Calibration() const {
  StereoCalibration s;
  s.left = left.Calibration("cam0");
  s.right = right.Calibration("cam1");
  return s;
}

Status CameraDeviceOptions::Validate() const {
  if (left.width != right.width || left.height != right.height) {
    return InvalidArgumentError("left is " + std::to_string(left.width) + "x" + std::to_string(left.height) +
                                " px, right " + std::to_string(right.width) + "x" + std::to_string(right.height) +
                                ": the pair's images must be of one size");
  }
  if ((aravis.width > 0 && aravis.width != left.width) || (aravis.height > 0 && aravis.height != left.height)) {
    return InvalidArgumentError("aravis asks the cameras for " + std::to_string(aravis.width) + "x" +
                                std::to_string(aravis.height) + " px, the calibration is of " +
                                std::to_string(left.width) + "x" + std::to_string(left.height));
  }
  if (Calibration().baseline() < 1e-3) {
    return InvalidArgumentError("left.T_body_cam and right.T_body_cam put the cameras less than 1 mm apart");
  }
  return Status::Ok();
}

}  // namespace cairn
