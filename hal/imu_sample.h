#pragma once

#include <Eigen/Core>

#include "common/timestamp.h"

namespace cairn {

// One IMU reading in the IMU's own frame (SI units: m/s^2, rad/s).
struct ImuSample {
  Timestamp time;
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
};

}  // namespace cairn
