#pragma once
// Calibration types. Every sensor carries T_body_sensor: the pose of the sensor frame in the body
// frame (maps sensor coordinates to body coordinates). The body frame is the IMU frame unless a
// robot profile says otherwise.

#include <array>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hal/wheel_odometry_sample.h"

namespace cairn {

// Pinhole camera with radial-tangential (plumb bob) distortion: k1, k2 radial, p1, p2 tangential.
struct PinholeRadTan {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0;

  // Distorts a point on the normalized image plane (z = 1).
  Eigen::Vector2d Distort(const Eigen::Vector2d& undistorted) const;
  // Inverts Distort by fixed-point iteration; converges for the moderate distortion of
  // navigation lenses (it is not meant for fisheye).
  Eigen::Vector2d Undistort(const Eigen::Vector2d& distorted) const;
  // Pixel of a point in the camera frame (z forward); requires p.z() > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam) const;
};

struct CameraCalibration {
  std::string name;
  PinholeRadTan intrinsics;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
};

struct StereoCalibration {
  CameraCalibration left;
  CameraCalibration right;

  Eigen::Isometry3d T_left_right() const { return left.T_body_cam.inverse() * right.T_body_cam; }
  double baseline() const { return T_left_right().translation().norm(); }
};

// Continuous-time noise densities and bias random walks as on an IMU data sheet or from an Allan
// variance analysis (the units are those of EuRoC's sensor.yaml).
struct ImuCalibration {
  Eigen::Isometry3d T_body_imu = Eigen::Isometry3d::Identity();
  double rate_hz = 200.0;
  double gyro_noise_density = 0.0;    // rad / s / sqrt(Hz)
  double gyro_random_walk = 0.0;      // rad / s^2 / sqrt(Hz)
  double accel_noise_density = 0.0;   // m / s^2 / sqrt(Hz)
  double accel_random_walk = 0.0;     // m / s^3 / sqrt(Hz)
};

// Wheel contact points in the body frame, for wheel-odometry kinematics.
struct WheelCalibration {
  int wheel_count = 0;
  std::array<Eigen::Vector2d, kMaxWheels> p_body_wheel{};
  double speed_noise = 0.0;  // m/s, one sigma per wheel
};

}  // namespace cairn
