#pragma once
// Shared pieces of the filter tests (header-only, test binaries only): a filter started from a
// simulator's truth with a random initial error drawn from its covariance, truth errors in the
// filter's error-state convention, and noisy relative-pose measurements.

#include <limits>
#include <random>

#include "estimation/filter/local_reference_filter.h"
#include "estimation/math/small_cholesky.h"
#include "estimation/math/so3.h"
#include "sim/imu_simulator.h"

namespace cairn::testing {

inline ImuNoise TestNoise() {
  // EuRoC's ADIS16448 figures, so simulated runs look like the real data.
  return {1.6968e-4, 1.9393e-5, 2.0e-3, 3.0e-3};
}

inline ImuCalibration TestCalibration() {
  ImuCalibration c;
  const ImuNoise n = TestNoise();
  c.gyro_noise_density = n.gyro_noise_density;
  c.gyro_random_walk = n.gyro_random_walk;
  c.accel_noise_density = n.accel_noise_density;
  c.accel_random_walk = n.accel_random_walk;
  return c;
}

inline Eigen::Matrix<double, 15, 15> InitialCovariance() {
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << 0.02, 0.02, 0.02, 0.05, 0.05, 0.05, 0.01, 0.01, 0.01, 0.05, 0.05, 0.05, 0.002, 0.002,
      0.002;
  return sigma.array().square().matrix().asDiagonal();
}

// Starts `filter` at the simulator's first sample with an initial error ~ N(0, P0).
inline ImuSample StartFromTruth(ImuSimulator& sim, LocalReferenceFilter& filter, std::mt19937_64& rng) {
  const ImuSample first = sim.Next();
  const TrajectoryPoint& t = sim.truth();
  const Eigen::Matrix<double, 15, 15> P0 = InitialCovariance();
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 15, 1> z;
  for (int i = 0; i < 15; ++i) z[i] = n(rng);
  Eigen::Matrix<double, 15, 15> L;
  small_cholesky::Factor<15>(P0, &L);
  const Eigen::Matrix<double, 15, 1> e = L * z;
  // Estimate = truth - error (error = truth - estimate; attitude: R_true = R_est Exp(e)).
  const Eigen::Quaterniond q = t.q * so3::ExpQuaternion(-e.segment<3>(kTheta));
  filter.Initialize(first.time, t.p - e.segment<3>(kP), t.v - e.segment<3>(kV), q,
                    sim.accel_bias() - e.segment<3>(kBa), sim.gyro_bias() - e.segment<3>(kBg), P0,
                    first);
  return first;
}

// Truth error [p, v, theta] of the IMU state with truth pose/velocity given in the filter frame.
inline Eigen::Matrix<double, 9, 1> StateError(const FilterState& s, const Eigen::Vector3d& p,
                                              const Eigen::Vector3d& v, const Eigen::Quaterniond& q) {
  Eigen::Matrix<double, 9, 1> e;
  e.segment<3>(0) = p - s.p;
  e.segment<3>(3) = v - s.v;
  e.segment<3>(6) = so3::Log(s.q.conjugate() * q);
  return e;
}

inline double Nees(const FilterState& s, const Eigen::Matrix<double, 9, 1>& e) {
  const Eigen::Matrix<double, 9, 9> P = s.P.topLeftCorner<9, 9>();
  Eigen::Matrix<double, 9, 9> L;
  if (!small_cholesky::Factor<9>(P, &L)) return std::numeric_limits<double>::infinity();
  Eigen::Matrix<double, 9, 1> z = e;
  small_cholesky::SolveLower<9>(L, z);
  return z.squaredNorm();
}

// A relative pose between two truth poses, perturbed by noise drawn from `cov`.
inline Eigen::Isometry3d NoisyRelativePose(const TrajectoryPoint& a, const TrajectoryPoint& b,
                                           const Matrix6d& cov, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vector6d z;
  for (int i = 0; i < 6; ++i) z[i] = n(rng);
  Matrix6d L;
  small_cholesky::Factor<6>(cov, &L);
  const Vector6d e = L * z;
  const Eigen::Matrix3d Ra = a.q.toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Ra.transpose() * b.q.toRotationMatrix()) * so3::Exp(e.tail<3>());
  T.translation() = Ra.transpose() * (b.p - a.p) + e.head<3>();
  return T;
}

// Two-sided 95 % band of a chi-square variable with `dof` degrees of freedom divided by `n`
// (Wilson-Hilferty approximation, accurate to well under 1 % for dof >= 30).
inline std::pair<double, double> ChiSquareBand95(double dof, double n) {
  auto quantile = [dof](double z) {
    const double h = 2.0 / (9.0 * dof);
    const double c = 1.0 - h + z * std::sqrt(h);
    return dof * c * c * c;
  };
  return {quantile(-1.959964) / n, quantile(1.959964) / n};
}

}  // namespace cairn::testing
