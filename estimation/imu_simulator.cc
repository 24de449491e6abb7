#include "estimation/imu_simulator.h"

#include <cmath>

namespace cairn {

ImuSimulator::ImuSimulator(const ImuSimulatorOptions& options)
    : options_(options),
      rng_(options.seed),
      ba_(options.initial_accel_bias),
      bg_(options.initial_gyro_bias) {}

TrajectoryPoint ImuSimulator::Truth(double t) const {
  const double s = options_.motion_scale;
  TrajectoryPoint out;
  out.t = t;
  // Position: a sum of sinusoids per axis, amplitude a, frequency w, phase c.
  const double amp[3] = {2.0 * s, 1.5 * s, 0.3 * s};
  const double w[3] = {0.4, 0.55, 0.9};
  const double ph[3] = {0.0, 0.7, 1.3};
  for (int i = 0; i < 3; ++i) {
    out.p[i] = amp[i] * std::sin(w[i] * t + ph[i]);
    out.v[i] = amp[i] * w[i] * std::cos(w[i] * t + ph[i]);
    out.a[i] = -amp[i] * w[i] * w[i] * std::sin(w[i] * t + ph[i]);
  }
  // Attitude: yaw, pitch, roll (ZYX) with their rates.
  const double yaw = 0.8 * s * std::sin(0.3 * t) + 0.3;
  const double yaw_d = 0.8 * s * 0.3 * std::cos(0.3 * t);
  const double pitch = 0.15 * s * std::sin(0.7 * t + 0.5) + 0.05;
  const double pitch_d = 0.15 * s * 0.7 * std::cos(0.7 * t + 0.5);
  const double roll = 0.2 * s * std::sin(0.9 * t + 1.1) - 0.08;
  const double roll_d = 0.2 * s * 0.9 * std::cos(0.9 * t + 1.1);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d R = Rz * Ry * Rx;
  out.q = Eigen::Quaterniond(R);
  const Eigen::Vector3d omega_world = yaw_d * Eigen::Vector3d::UnitZ() +
                                      pitch_d * (Rz * Eigen::Vector3d::UnitY()) +
                                      roll_d * (Rz * Ry * Eigen::Vector3d::UnitX());
  out.omega_body = R.transpose() * omega_world;
  return out;
}

ImuSample ImuSimulator::Next() {
  const Timestamp stamp = options_.start + Duration::Nanoseconds(static_cast<int64_t>(
                                               std::llround(static_cast<double>(index_) * 1e9 / options_.rate_hz)));
  if (index_ > 0 && options_.add_noise) {
    // Bias random walks over one sample period.
    const double sdt = std::sqrt(dt());
    for (int i = 0; i < 3; ++i) {
      ba_[i] += options_.noise.accel_random_walk * sdt * normal_(rng_);
      bg_[i] += options_.noise.gyro_random_walk * sdt * normal_(rng_);
    }
  }
  ++index_;
  truth_ = Truth((stamp - options_.start).seconds());
  ImuSample s;
  s.time = stamp;
  const Eigen::Matrix3d R = truth_.q.toRotationMatrix();
  s.accel = R.transpose() * (truth_.a + Eigen::Vector3d(0.0, 0.0, options_.gravity)) + ba_;
  s.gyro = truth_.omega_body + bg_;
  if (options_.add_noise) {
    const double k = 1.0 / std::sqrt(dt());
    for (int i = 0; i < 3; ++i) {
      s.accel[i] += options_.noise.accel_noise_density * k * normal_(rng_);
      s.gyro[i] += options_.noise.gyro_noise_density * k * normal_(rng_);
    }
  }
  return s;
}

}  // namespace cairn
