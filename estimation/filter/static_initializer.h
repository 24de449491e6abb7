#pragma once
// Static initialization from a still period: roll and pitch from the mean specific force, gyro
// bias from the mean rate, yaw zero (the local frame's yaw is arbitrary).
//
// Samples are averaged in blocks of init_block seconds first, so that vibration (a multicopter
// idling on the ground) does not count as motion. Policy when the robot moves: a block whose mean
// rate or specific force leaves the window's mean (init_max_gyro_dev, init_max_accel_dev), whose
// mean rate exceeds init_max_gyro or whose mean specific force is further than
// init_max_accel_dev from gravity in magnitude restarts the window, and so do wheels that turn
// (init_max_wheel_speed): a rover driving at constant speed looks still to its IMU. The filter
// reports "not initialized" until a full window has been collected; it never initializes from
// moving data, because a wrong gravity direction would corrupt every later estimate. A robot that
// cannot stand still is initialized explicitly with LocalReferenceFilter::Initialize().

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/filter/filter_options.h"
#include "hal/imu_sample.h"

namespace cairn {

class StaticInitializer {
 public:
  explicit StaticInitializer(const FilterOptions& options) : options_(options) {}

  // Returns true when the sample completes a still window.
  bool Add(const ImuSample& sample);
  // Body x/y velocity from the wheels, with covariance: a speed above init_max_wheel_speed that
  // is also far outside the encoder noise (chi-square, 2 degrees of freedom, 99.97 %) is motion,
  // and the window restarts.
  void AddBodyVelocity(const Eigen::Vector2d& v_xy, const Eigen::Matrix2d& covariance);
  void Reset();

  const Eigen::Vector3d& mean_accel() const { return mean_accel_; }
  const Eigen::Vector3d& mean_gyro() const { return mean_gyro_; }
  // Gravity-aligned IMU attitude with zero yaw.
  Eigen::Quaterniond Attitude() const;
  int restarts() const { return restarts_; }

 private:
  FilterOptions options_;
  Timestamp start_, block_start_;
  int count_ = 0;
  int block_count_ = 0;
  Eigen::Vector3d block_accel_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d block_gyro_ = Eigen::Vector3d::Zero();
  int restarts_ = 0;
  Eigen::Vector3d sum_accel_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_gyro_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_accel_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_gyro_ = Eigen::Vector3d::Zero();
};

}  // namespace cairn
