#include "estimation/filter/static_initializer.h"

#include <cmath>

#include <Eigen/Cholesky>

namespace cairn {

void StaticInitializer::Reset() {
  count_ = 0;
  block_count_ = 0;
  sum_accel_.setZero();
  sum_gyro_.setZero();
  block_accel_.setZero();
  block_gyro_.setZero();
}

void StaticInitializer::AddBodyVelocity(const Eigen::Vector2d& v_xy, const Eigen::Matrix2d& covariance) {
  if (!v_xy.allFinite() || v_xy.norm() <= options_.init_max_wheel_speed) return;
  const Eigen::LLT<Eigen::Matrix2d> llt(covariance);
  if (llt.info() != Eigen::Success || !(v_xy.dot(llt.solve(v_xy)) > 16.0)) return;
  if (count_ > 0) ++restarts_;
  Reset();
}

bool StaticInitializer::Add(const ImuSample& sample) {
  if (block_count_ == 0) block_start_ = sample.time;
  if (count_ == 0 && block_count_ == 0) start_ = sample.time;
  ++block_count_;
  block_accel_ += sample.accel;
  block_gyro_ += sample.gyro;
  if ((sample.time - block_start_).seconds() < options_.init_block) return false;

  const Eigen::Vector3d a = block_accel_ / block_count_;
  const Eigen::Vector3d w = block_gyro_ / block_count_;
  bool still = w.norm() <= options_.init_max_gyro &&
               std::abs(a.norm() - options_.gravity) <= options_.init_max_accel_dev;
  if (still && count_ > 0) {
    still = (w - sum_gyro_ / count_).norm() <= options_.init_max_gyro_dev &&
            (a - sum_accel_ / count_).norm() <= options_.init_max_accel_dev;
  }
  if (!still) {
    if (count_ > 0) ++restarts_;
    Reset();
    return false;
  }
  count_ += block_count_;
  sum_accel_ += block_accel_;
  sum_gyro_ += block_gyro_;
  block_count_ = 0;
  block_accel_.setZero();
  block_gyro_.setZero();
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
