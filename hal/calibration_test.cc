#include "hal/calibration.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

// EuRoC cam0 (V1_01_easy) intrinsics: a real lens with strong barrel distortion.
PinholeRadTan EurocCam0() {
  PinholeRadTan c;
  c.width = 752; c.height = 480;
  c.fx = 458.654; c.fy = 457.296; c.cx = 367.215; c.cy = 248.375;
  c.k1 = -0.28340811; c.k2 = 0.07395907; c.p1 = 0.00019359; c.p2 = 1.76187114e-05;
  return c;
}

TEST(CalibrationTest, UndistortInvertsDistortAcrossTheImage) {
  const PinholeRadTan cam = EurocCam0();
  for (double x = -0.7; x <= 0.7; x += 0.1) {
    for (double y = -0.5; y <= 0.5; y += 0.1) {
      const Eigen::Vector2d u(x, y);
      EXPECT_LT((cam.Undistort(cam.Distort(u)) - u).norm(), 1e-9) << x << " " << y;
    }
  }
}

TEST(CalibrationTest, ProjectOpticalAxisHitsPrincipalPoint) {
  const PinholeRadTan cam = EurocCam0();
  const Eigen::Vector2d px = cam.Project({0.0, 0.0, 3.0});
  EXPECT_NEAR(px.x(), cam.cx, 1e-12);
  EXPECT_NEAR(px.y(), cam.cy, 1e-12);
  // Barrel distortion pulls off-axis points towards the centre.
  const Eigen::Vector2d off = cam.Project({0.5, 0.0, 1.0});
  EXPECT_LT(off.x() - cam.cx, cam.fx * 0.5);
}

TEST(CalibrationTest, StereoBaselineFromExtrinsics) {
  StereoCalibration s;
  s.left.T_body_cam.translation() = Eigen::Vector3d(0.0, 0.05, 0.0);
  s.right.T_body_cam.translation() = Eigen::Vector3d(0.0, -0.04, 0.0);
  EXPECT_NEAR(s.baseline(), 0.09, 1e-15);
  EXPECT_NEAR(s.T_left_right().translation().y(), -0.09, 1e-15);
}

}  // namespace
}  // namespace cairn
