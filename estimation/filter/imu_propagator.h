#pragma once
// Strapdown integration and error-covariance propagation over one interval between two IMU
// readings. The readings are taken as linear in time over the interval (trapezoidal rule), which
// makes the nominal integration second order; the error model is the continuous-time linearized
// model discretized over the interval, applied block-wise (the transition matrix is sparse).

#include <Eigen/Core>

#include "estimation/filter/filter_state.h"
#include "hal/calibration.h"

namespace cairn {

struct ImuNoise {
  double gyro_noise_density = 0.0;   // rad/s/sqrt(Hz)
  double gyro_random_walk = 0.0;     // rad/s^2/sqrt(Hz)
  double accel_noise_density = 0.0;  // m/s^2/sqrt(Hz)
  double accel_random_walk = 0.0;    // m/s^3/sqrt(Hz)

  static ImuNoise FromCalibration(const ImuCalibration& c) {
    return {c.gyro_noise_density, c.gyro_random_walk, c.accel_noise_density, c.accel_random_walk};
  }
};

class ImuPropagator {
 public:
  ImuPropagator(const ImuNoise& noise, double gravity);

  // Advances `s` from s.time (reading s.accel/s.gyro) to `t1` with reading (accel1, gyro1).
  // Does nothing for t1 <= s.time.
  void Propagate(FilterState& s, Timestamp t1, const Eigen::Vector3d& accel1,
                 const Eigen::Vector3d& gyro1) const;

  const Eigen::Vector3d& gravity() const { return gravity_; }

 private:
  ImuNoise noise_;
  Eigen::Vector3d gravity_;
};

}  // namespace cairn
