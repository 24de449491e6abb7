#include "estimation/imu_propagator.h"

#include "estimation/so3.h"

namespace cairn {
namespace {

// The non-trivial 3x3 blocks of the 15x15 transition matrix Phi.
struct Transition {
  double dt = 0.0;
  Eigen::Matrix3d p_theta, p_ba, v_theta, v_ba, theta_theta, theta_bg;
};

// X <- Phi * X for a matrix with 15 rows, in place. The row blocks are updated in the order
// p, v, theta so that each only reads blocks not yet overwritten.
template <int Cols>
void ApplyTransitionRows(const Transition& f, Eigen::Matrix<double, kCoreDim, Cols>& x) {
  using Rows = Eigen::Matrix<double, 3, Cols>;
  const Rows v = x.template middleRows<3>(kV);
  const Rows th = x.template middleRows<3>(kTheta);
  const Rows ba = x.template middleRows<3>(kBa);
  const Rows bg = x.template middleRows<3>(kBg);
  x.template middleRows<3>(kP).noalias() += f.dt * v + f.p_theta * th + f.p_ba * ba;
  x.template middleRows<3>(kV).noalias() += f.v_theta * th + f.v_ba * ba;
  x.template middleRows<3>(kTheta).noalias() = f.theta_theta * th + f.theta_bg * bg;
}

}  // namespace

ImuPropagator::ImuPropagator(const ImuNoise& noise, double gravity)
    : noise_(noise), gravity_(0.0, 0.0, -gravity) {}

void ImuPropagator::Propagate(FilterState& s, Timestamp t1, const Eigen::Vector3d& accel1,
                              const Eigen::Vector3d& gyro1) const {
  const double dt = (t1 - s.time).seconds();
  if (dt <= 0.0) return;

  // Nominal strapdown: rotation with the mean rate, specific force by the trapezoidal rule over
  // the rotated start and end readings.
  const Eigen::Vector3d w = 0.5 * (s.gyro + gyro1) - s.bg;
  const Eigen::Vector3d a0 = s.accel - s.ba;
  const Eigen::Vector3d a1 = accel1 - s.ba;
  const Eigen::Matrix3d R0 = s.q.toRotationMatrix();
  const Eigen::Vector3d phi = w * dt;
  const Eigen::Quaterniond dq = so3::ExpQuaternion(phi);
  const Eigen::Quaterniond q1 = (s.q * dq).normalized();
  const Eigen::Matrix3d R1 = q1.toRotationMatrix();
  const Eigen::Vector3d acc_world = 0.5 * (R0 * a0 + R1 * a1) + gravity_;
  s.p += s.v * dt + 0.5 * acc_world * dt * dt;
  s.v += acc_world * dt;
  s.q = q1;

  // Error transition, linearized about the mid-interval attitude and mean specific force.
  const Eigen::Matrix3d R_mid = (s.q.slerp(0.5, Eigen::Quaterniond(R0))).toRotationMatrix();
  const Eigen::Vector3d a_mean = 0.5 * (a0 + a1);
  Transition f;
  f.dt = dt;
  f.v_theta = -R_mid * so3::Skew(a_mean) * dt;
  f.v_ba = -R_mid * dt;
  f.p_theta = 0.5 * dt * f.v_theta;
  f.p_ba = 0.5 * dt * f.v_ba;
  f.theta_theta = dq.toRotationMatrix().transpose();
  f.theta_bg = -so3::RightJacobian(phi) * dt;

  // P_core <- Phi P_core Phi^T + Q; the cross block with the clones is deferred (phi <- Phi phi).
  Eigen::Matrix<double, kCoreDim, kCoreDim> half = s.P.topLeftCorner<kCoreDim, kCoreDim>();
  ApplyTransitionRows(f, half);
  Eigen::Matrix<double, kCoreDim, kCoreDim> core = half.transpose();
  ApplyTransitionRows(f, core);
  ApplyTransitionRows(f, s.phi);
  s.cross_pending = true;

  const double qa = noise_.accel_noise_density * noise_.accel_noise_density;
  const double qg = noise_.gyro_noise_density * noise_.gyro_noise_density;
  const double qba = noise_.accel_random_walk * noise_.accel_random_walk;
  const double qbg = noise_.gyro_random_walk * noise_.gyro_random_walk;
  const double dt2 = dt * dt;
  core.block<3, 3>(kP, kP).diagonal().array() += qa * dt2 * dt / 3.0;
  core.block<3, 3>(kP, kV).diagonal().array() += qa * dt2 / 2.0;
  core.block<3, 3>(kV, kP).diagonal().array() += qa * dt2 / 2.0;
  core.block<3, 3>(kV, kV).diagonal().array() += qa * dt;
  core.block<3, 3>(kTheta, kTheta).diagonal().array() += qg * dt;
  core.block<3, 3>(kBa, kBa).diagonal().array() += qba * dt;
  core.block<3, 3>(kBg, kBg).diagonal().array() += qbg * dt;
  s.P.topLeftCorner<kCoreDim, kCoreDim>() = 0.5 * (core + core.transpose());

  s.time = t1;
  s.accel = accel1;
  s.gyro = gyro1;
}

}  // namespace cairn
