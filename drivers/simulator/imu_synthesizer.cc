#include "drivers/simulator/imu_synthesizer.h"

#include <cmath>

#include "drivers/simulator/sim_random.h"

namespace cairn::sim {

ImuSynthesizer::ImuSynthesizer(const ImuCalibration& calibration, uint64_t seed, bool noise)
    : calibration_(calibration), seed_(seed), noise_(noise) {}

void ImuSynthesizer::Exact(const TrajectoryState& s, Eigen::Vector3d* accel, Eigen::Vector3d* gyro) {
  const Eigen::Matrix3d R = s.T_world_body.linear();
  *accel = R.transpose() * (s.acceleration + Eigen::Vector3d(0, 0, kGravity));
  *gyro = s.omega_body;
}

std::vector<ImuTruth> ImuSynthesizer::Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                               double duration) {
  const double rate = calibration_.rate_hz, dt = 1.0 / rate;
  const int64_t count = static_cast<int64_t>(std::floor(duration * rate + 1e-9)) + 1;
  const int64_t period_ns = std::llround(1e9 / rate);
  // Discrete-time equivalents of the continuous densities.
  const double sg = calibration_.gyro_noise_density / std::sqrt(dt);
  const double sa = calibration_.accel_noise_density / std::sqrt(dt);
  const double rg = calibration_.gyro_random_walk * std::sqrt(dt);
  const double ra = calibration_.accel_random_walk * std::sqrt(dt);
  SimRandom rng(seed_);
  // z, y, x: one noise sequence whatever order a compiler evaluates arguments in (GCC's order, so
  // earlier missions keep their IMU data).
  auto normal3 = [&] {
    const double z = rng.Normal();
    const double y = rng.Normal();
    const double x = rng.Normal();
    return Eigen::Vector3d(x, y, z);
  };
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero();
  if (noise_) {
    // Turn-on biases of a few times the in-run walk over a minute.
    bg = normal3() * (calibration_.gyro_random_walk * 8.0);
    ba = normal3() * (calibration_.accel_random_walk * 8.0);
  }
  std::vector<ImuTruth> out;
  out.reserve(static_cast<size_t>(count));
  for (int64_t k = 0; k < count; ++k) {
    ImuTruth r;
    // Time from integer nanoseconds so that sample times and camera times agree exactly.
    r.sample.time = start + Duration::Nanoseconds(k * period_ns);
    r.state = trajectory.Evaluate(static_cast<double>(k * period_ns) * 1e-9);
    Exact(r.state, &r.sample.accel, &r.sample.gyro);
    if (noise_) {
      r.sample.gyro += bg + sg * normal3();
      r.sample.accel += ba + sa * normal3();
    }
    r.gyro_bias = bg;
    r.accel_bias = ba;
    out.push_back(r);
    if (noise_) {
      bg += rg * normal3();
      ba += ra * normal3();
    }
  }
  return out;
}

}  // namespace cairn::sim
