#pragma once
// Simulated IMU readings along a smooth trajectory: the exact specific force and angular rate in
// the body (= IMU) frame, plus discrete white noise and bias random walks derived from the
// continuous-time densities of an ImuCalibration. The one IMU model of the simulator: the mission
// simulator generates a robot's samples over its B-spline, and ImuSimulator streams samples along
// an AnalyticTrajectory for the filter tests.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "hal/calibration.h"
#include "hal/imu_sample.h"
#include "sim/bspline_trajectory.h"
#include "sim/sim_random.h"

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
  // With `noise` the biases start from random turn-on values and walk; without, the readings are
  // exact plus constant biases (zero unless SetBiases), for consistency checks.
  ImuSynthesizer(const ImuCalibration& calibration, uint64_t seed, bool noise = true);

  // Replaces the biases in effect at the next sample.
  void SetBiases(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel);

  // The reading at `time` of the IMU moving as `state` says, with the biases in effect and white
  // noise; the biases then walk on for one sample period. Allocates nothing, for streaming.
  ImuTruth Sample(Timestamp time, const TrajectoryState& state);

  // Samples at t_k = k / rate for k = 0 .. floor(duration * rate); times are start + t_k. The
  // noise continues this synthesizer's sequence (a new synthesizer: the mission's IMU data).
  std::vector<ImuTruth> Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                 double duration);

  // The noise-free reading for a trajectory state.
  static void Exact(const TrajectoryState& s, Eigen::Vector3d* accel, Eigen::Vector3d* gyro);

 private:
  Eigen::Vector3d Normal3();

  ImuCalibration calibration_;
  bool noise_;
  SimRandom rng_;
  // Discrete-time equivalents of the continuous densities: white noise sigmas per sample (gyro,
  // accel) and bias random walk sigmas per sample period.
  double sg_ = 0.0, sa_ = 0.0, rg_ = 0.0, ra_ = 0.0;
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero(), ba_ = Eigen::Vector3d::Zero();
};

}  // namespace cairn::sim
