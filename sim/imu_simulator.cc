#include "sim/imu_simulator.h"

#include <cmath>

namespace cairn {
namespace {

ImuCalibration Calibration(const ImuSimulatorOptions& o) {
  ImuCalibration c;
  c.rate_hz = o.rate_hz;
  c.gyro_noise_density = o.noise.gyro_noise_density;
  c.gyro_random_walk = o.noise.gyro_random_walk;
  c.accel_noise_density = o.noise.accel_noise_density;
  c.accel_random_walk = o.noise.accel_random_walk;
  return c;
}

TrajectoryPoint ToPoint(double t, const sim::TrajectoryState& s) {
  TrajectoryPoint out;
  out.t = t;
  out.p = s.T_world_body.translation();
  out.v = s.velocity;
  out.a = s.acceleration;
  out.q = Eigen::Quaterniond(s.T_world_body.linear());
  out.omega_body = s.omega_body;
  return out;
}

}  // namespace

ImuSimulator::ImuSimulator(const ImuSimulatorOptions& options)
    : options_(options),
      trajectory_(options.motion_scale),
      imu_(Calibration(options), options.seed, options.add_noise),
      ba_(options.initial_accel_bias),
      bg_(options.initial_gyro_bias) {
  // The given initial biases replace the synthesizer's random turn-on biases.
  imu_.SetBiases(options.initial_gyro_bias, options.initial_accel_bias);
}

TrajectoryPoint ImuSimulator::Truth(double t) const { return ToPoint(t, trajectory_.Evaluate(t)); }

ImuSample ImuSimulator::Next() {
  const Timestamp stamp = options_.start + Duration::Nanoseconds(static_cast<int64_t>(
                                               std::llround(static_cast<double>(index_) * 1e9 / options_.rate_hz)));
  ++index_;
  const double t = (stamp - options_.start).seconds();
  const sim::ImuTruth r = imu_.Sample(stamp, trajectory_.Evaluate(t));
  truth_ = ToPoint(t, r.state);
  ba_ = r.accel_bias;
  bg_ = r.gyro_bias;
  return r.sample;
}

}  // namespace cairn
