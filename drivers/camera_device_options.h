#pragma once
// `cameras:` of a profile: the robot's stereo pair for source: live, its calibration and its
// driver. Replays take cameras and calibration from the recording, the simulator from its robot.

#include <cstdint>
#include <string>
#include <vector>

#include "common/options_visitor.h"
#include "drivers/aravis_camera_options.h"
#include "hal/calibration.h"

namespace cairn {

// One camera of the pair: pinhole with radial-tangential distortion, and its pose on the robot.
struct CameraIntrinsicsOptions {
  int64_t width = 640;   // px
  int64_t height = 480;  // px
  double fx = 500.0, fy = 500.0, cx = 319.5, cy = 239.5;  // px
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0;
  // The camera (z forward, x right, y down) in the body frame: x, y, z (m), then roll, pitch, yaw
  // (rad, applied z-y-x), as imu.T_body_imu.
  std::vector<double> T_body_cam = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};

  void Visit(OptionsVisitor& v) {
    v.Integer("width", width, 1, 65535, "px");
    v.Integer("height", height, 1, 65535, "px");
    v.Number("fx", fx, 1.0, 1e6, "px");
    v.Number("fy", fy, 1.0, 1e6, "px");
    v.Number("cx", cx, -1e5, 1e5, "px");
    v.Number("cy", cy, -1e5, 1e5, "px");
    v.Number("k1", k1, -10.0, 10.0, "");
    v.Number("k2", k2, -10.0, 10.0, "");
    v.Number("p1", p1, -1.0, 1.0, "");
    v.Number("p2", p2, -1.0, 1.0, "");
    v.Numbers("T_body_cam", T_body_cam, 6, 6, -100.0, 100.0, "m, rad");
  }
  CameraCalibration Calibration(const std::string& name) const;
};

enum class CameraDriverKind { kAravis };

struct CameraDeviceOptions {
  bool enabled = false;
  CameraDriverKind driver = CameraDriverKind::kAravis;
  CameraIntrinsicsOptions left;
  CameraIntrinsicsOptions right;
  AravisCameraOptions aravis;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Choice("driver", driver, {{"aravis", CameraDriverKind::kAravis}});
    v.Section("left", left);
    v.Section("right", right);
    v.Section("aravis", aravis);
  }
  StereoCalibration Calibration() const;
  // The two cameras' images of one size, matching the driver's, and a baseline between them.
  Status Validate() const;
};

}  // namespace cairn
