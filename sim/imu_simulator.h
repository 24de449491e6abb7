#pragma once
// IMU samples streamed one at a time along the AnalyticTrajectory, with ImuSynthesizer's sensor
// model (exact readings, white noise and bias random walks per the noise densities), and the truth
// as filter tests want it. For filter tests and benchmarks; allocates nothing per sample. The world
// frame is gravity aligned with gravity (sim::kGravity) along -z.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/filter/imu_propagator.h"
#include "hal/imu_sample.h"
#include "sim/analytic_trajectory.h"
#include "sim/imu_synthesizer.h"

namespace cairn {

struct TrajectoryPoint {
  double t = 0.0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // world acceleration
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();
};

struct ImuSimulatorOptions {
  double rate_hz = 200.0;
  double motion_scale = 1.0;  // 0 = at rest
  ImuNoise noise;
  bool add_noise = true;  // false: exact readings plus the constant initial biases
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d::Zero();
  uint64_t seed = 1;
  Timestamp start = Timestamp::FromSeconds(100.0);
};

class ImuSimulator {
 public:
  explicit ImuSimulator(const ImuSimulatorOptions& options);

  TrajectoryPoint Truth(double t) const;  // t in s since start
  // The next IMU sample (the first is at the start time).
  ImuSample Next();
  // Truth at the last sample returned, and the biases in effect there.
  const TrajectoryPoint& truth() const { return truth_; }
  const Eigen::Vector3d& accel_bias() const { return ba_; }
  const Eigen::Vector3d& gyro_bias() const { return bg_; }
  Timestamp TimeOf(double t) const { return options_.start + Duration::Seconds(t); }
  double dt() const { return 1.0 / options_.rate_hz; }

 private:
  ImuSimulatorOptions options_;
  sim::AnalyticTrajectory trajectory_;
  sim::ImuSynthesizer imu_;
  int64_t index_ = 0;
  TrajectoryPoint truth_;
  Eigen::Vector3d ba_, bg_;
};

}  // namespace cairn
