#pragma once
// Simulated IMU readings from a smooth trajectory: the exact specific force and angular rate in
// the body (= IMU) frame, plus discrete white noise and bias random walks derived from the
// continuous-time densities of an ImuCalibration.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "drivers/simulator/bspline_trajectory.h"
#include "hal/calibration.h"
#include "hal/imu_sample.h"

namespace cairn::sim {

inline constexpr double kGravity = 9.81;  // m/s^2, world z up

struct ImuTruth {
  ImuSample sample;                 // what the sensor reports
  TrajectoryState state;            // ground truth at the same instant
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
};

class ImuSynthesizer {
 public:
  // `noise` false gives the exact readings (and zero biases), for consistency checks.
  ImuSynthesizer(const ImuCalibration& calibration, uint64_t seed, bool noise = true);

  // Samples at t_k = k / rate for k = 0 .. floor(duration * rate); times are start + t_k.
  std::vector<ImuTruth> Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                 double duration);

  // The noise-free reading for a trajectory state.
  static void Exact(const TrajectoryState& s, Eigen::Vector3d* accel, Eigen::Vector3d* gyro);

 private:
  ImuCalibration calibration_;
  uint64_t seed_;
  bool noise_;
};

}  // namespace cairn::sim
