#pragma once
// `imu:` of a profile: the robot's IMU device, used when `source: live` (a replay takes the IMU from
// its recording, a simulated robot from the simulator): an Xsens MTi on a serial line
// (xsens_imu_driver.h, the rovers') or an IIO IMU such as the ADIS16407 (iio_imu_driver.h, the
// hexacopter's).

#include <vector>

#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "common/status.h"
#include "drivers/iio_imu_options.h"
#include "drivers/xsens_imu_options.h"
#include "drivers/xyz_rpy_pose.h"
#include "hal/calibration.h"

namespace cairn {

enum class ImuDriverKind { kXsens, kIio };

struct ImuDeviceOptions {
  bool enabled = false;
  ImuDriverKind driver = ImuDriverKind::kXsens;
  // The IMU in the body frame: x, y, z (m), then roll, pitch, yaw (rad, applied z-y-x).
  std::vector<double> T_body_imu = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  // Continuous-time noise of the device (datasheet or Allan variance), for the filter.
  double gyro_noise_density = 5.2e-4;   // rad/s/sqrt(Hz); MTi-10: 0.03 deg/s/sqrt(Hz)
  double gyro_random_walk = 1.0e-5;     // rad/s^2/sqrt(Hz)
  double accel_noise_density = 7.8e-4;  // m/s^2/sqrt(Hz); MTi-10: 80 ug/sqrt(Hz)
  double accel_random_walk = 1.0e-4;    // m/s^3/sqrt(Hz)
  XsensImuOptions xsens;
  IioImuOptions iio;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Choice("driver", driver, {{"xsens", ImuDriverKind::kXsens}, {"iio", ImuDriverKind::kIio}});
    v.Numbers("T_body_imu", T_body_imu, 6, 6, -100.0, 100.0, "m, rad");
    v.Number("gyro_noise_density", gyro_noise_density, 0.0, 1.0, "rad/s/sqrt(Hz)");
    v.Number("gyro_random_walk", gyro_random_walk, 0.0, 1.0, "rad/s^2/sqrt(Hz)");
    v.Number("accel_noise_density", accel_noise_density, 0.0, 10.0, "m/s^2/sqrt(Hz)");
    v.Number("accel_random_walk", accel_random_walk, 0.0, 10.0, "m/s^3/sqrt(Hz)");
    v.Section("xsens", xsens);
    v.Section("iio", iio);
  }

  ImuCalibration Calibration() const {
    ImuCalibration c;
    c.T_body_imu = PoseFromXyzRpy(T_body_imu);
    c.rate_hz = driver == ImuDriverKind::kXsens ? xsens.rate_hz : iio.rate_hz;
    c.gyro_noise_density = gyro_noise_density;
    c.gyro_random_walk = gyro_random_walk;
    c.accel_noise_density = accel_noise_density;
    c.accel_random_walk = accel_random_walk;
    return c;
  }
};

}  // namespace cairn
