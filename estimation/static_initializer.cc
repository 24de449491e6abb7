#include "estimation/static_initializer.h"

#include <cmath>

namespace cairn {

void StaticInitializer::Reset() {
  count_ = 0;
  sum_accel_.setZero();
  sum_gyro_.setZero();
}

bool StaticInitializer::Add(const ImuSample& sample) {
  const bool still = sample.gyro.norm() <= options_.init_max_gyro &&
                     std::abs(sample.accel.norm() - options_.gravity) <= options_.init_max_accel_dev;
  if (!still) {
    if (count_ > 0) ++restarts_;
    Reset();
    return false;
  }
  if (count_ == 0) start_ = sample.time;
  ++count_;
  sum_accel_ += sample.accel;
  sum_gyro_ += sample.gyro;
  if ((sample.time - start_).seconds() < options_.init_duration) return false;
  mean_accel_ = sum_accel_ / count_;
  mean_gyro_ = sum_gyro_ / count_;
  return true;
}

Eigen::Quaterniond StaticInitializer::Attitude() const {
  // At rest the accelerometer measures R^T * (0, 0, g): solve for roll and pitch.
  const Eigen::Vector3d f = mean_accel_.normalized();
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  return Eigen::Quaterniond(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

}  // namespace cairn
