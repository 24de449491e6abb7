#include "sim/imu_synthesizer.h"

#include <cmath>

namespace cairn::sim {

ImuSynthesizer::ImuSynthesizer(const ImuCalibration& calibration, uint64_t seed, bool noise)
    : calibration_(calibration), noise_(noise), rng_(seed) {
  const double dt = 1.0 / calibration_.rate_hz;
  sg_ = calibration_.gyro_noise_density / std::sqrt(dt);
  sa_ = calibration_.accel_noise_density / std::sqrt(dt);
  rg_ = calibration_.gyro_random_walk * std::sqrt(dt);
  ra_ = calibration_.accel_random_walk * std::sqrt(dt);
  if (noise_) {
    // Turn-on biases of a few times the in-run walk over a minute.
    bg_ = Normal3() * (calibration_.gyro_random_walk * 8.0);
    ba_ = Normal3() * (calibration_.accel_random_walk * 8.0);
  }
}

// z, y, x: one noise sequence whatever order a compiler evaluates arguments in (GCC's order, so
// earlier missions keep their IMU data).
Eigen::Vector3d ImuSynthesizer::Normal3() {
  const double z = rng_.Normal();
  const double y = rng_.Normal();
  const double x = rng_.Normal();
  return Eigen::Vector3d(x, y, z);
}

void ImuSynthesizer::SetBiases(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel) {
  bg_ = gyro;
  ba_ = accel;
}

void ImuSynthesizer::Exact(const TrajectoryState& s, Eigen::Vector3d* accel, Eigen::Vector3d* gyro) {
  const Eigen::Matrix3d R = s.T_world_body.linear();
  *accel = R.transpose() * (s.acceleration + Eigen::Vector3d(0, 0, kGravity));
  *gyro = s.omega_body;
}

ImuTruth ImuSynthesizer::Sample(Timestamp time, const TrajectoryState& state) {
  ImuTruth r;
  r.sample.time = time;
  r.state = state;
  Exact(r.state, &r.sample.accel, &r.sample.gyro);
  if (noise_) {
    r.sample.gyro += bg_ + sg_ * Normal3();
    r.sample.accel += ba_ + sa_ * Normal3();
  } else {
    r.sample.gyro += bg_;
    r.sample.accel += ba_;
  }
  r.gyro_bias = bg_;
  r.accel_bias = ba_;
  if (noise_) {
    bg_ += rg_ * Normal3();
    ba_ += ra_ * Normal3();
  }
  return r;
}

std::vector<ImuTruth> ImuSynthesizer::Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                               double duration) {
  const double rate = calibration_.rate_hz;
  const int64_t count = static_cast<int64_t>(std::floor(duration * rate + 1e-9)) + 1;
  const int64_t period_ns = std::llround(1e9 / rate);
  std::vector<ImuTruth> out;
  out.reserve(static_cast<size_t>(count));
  for (int64_t k = 0; k < count; ++k) {
    // Time from integer nanoseconds so that sample times and camera times agree exactly.
    out.push_back(Sample(start + Duration::Nanoseconds(k * period_ns),
                         trajectory.Evaluate(static_cast<double>(k * period_ns) * 1e-9)));
  }
  return out;
}

}  // namespace cairn::sim
