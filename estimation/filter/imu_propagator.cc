#include "estimation/filter/imu_propagator.h"

#include <cmath>
#include <cstddef>

#include "estimation/filter/filter_kernels.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

// The transition matrix Phi of the 15-dim core error state, by its non-trivial blocks:
//   dp' = dp + dt dv + dt/2 Fva (a x dtheta + dba)
//   dv' = dv + Fva (a x dtheta + dba)                  Fva = -R_mid dt
//   dtheta' = Ftt dtheta + Ftg dbg                     Ftt = Exp(w dt)^T, Ftg = -Jr(w dt) dt
//   dba' = dba, dbg' = dbg
struct Transition {
  double dt = 0.0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // mean bias-corrected specific force (IMU frame)
  Eigen::Matrix3d Fva, Ftt, Ftg;
};

// M <- M Phi^T for a column-major matrix M with `Rows` rows and 15 columns (leading dimension
// ld): each row is one error vector, so the work is a few axpy over contiguous columns, done for
// `Lanes` rows (from row i) at a time, in place. Applied to the transpose of a matrix, this is the
// left-multiplication Phi X.
template <int Lanes>
[[gnu::always_inline]] inline void TransitionRow(const Transition& f, double* m, int ld, int i) {
  using T = typename kernels::Unaligned<Lanes>::type;
  T* col[kCoreDim];
  for (int c = 0; c < kCoreDim; ++c) col[c] = reinterpret_cast<T*>(m + static_cast<ptrdiff_t>(c) * ld + i);
  const double a0 = f.a.x(), a1 = f.a.y(), a2 = f.a.z();
  const Eigen::Matrix3d& F = f.Fva;
  const Eigen::Matrix3d& R = f.Ftt;
  const Eigen::Matrix3d& G = f.Ftg;
  const T th0 = *col[6], th1 = *col[7], th2 = *col[8];
  const T z0 = a1 * th2 - a2 * th1 + *col[9];
  const T z1 = a2 * th0 - a0 * th2 + *col[10];
  const T z2 = a0 * th1 - a1 * th0 + *col[11];
  const T g0 = *col[12], g1 = *col[13], g2 = *col[14];
  *col[6] = R(0, 0) * th0 + R(0, 1) * th1 + R(0, 2) * th2 + G(0, 0) * g0 + G(0, 1) * g1 + G(0, 2) * g2;
  *col[7] = R(1, 0) * th0 + R(1, 1) * th1 + R(1, 2) * th2 + G(1, 0) * g0 + G(1, 1) * g1 + G(1, 2) * g2;
  *col[8] = R(2, 0) * th0 + R(2, 1) * th1 + R(2, 2) * th2 + G(2, 0) * g0 + G(2, 1) * g1 + G(2, 2) * g2;
  const T d0 = F(0, 0) * z0 + F(0, 1) * z1 + F(0, 2) * z2;
  const T d1 = F(1, 0) * z0 + F(1, 1) * z1 + F(1, 2) * z2;
  const T d2 = F(2, 0) * z0 + F(2, 1) * z1 + F(2, 2) * z2;
  const double dt = f.dt, hdt = 0.5 * f.dt;
  *col[0] = *col[0] + dt * *col[3] + hdt * d0;
  *col[1] = *col[1] + dt * *col[4] + hdt * d1;
  *col[2] = *col[2] + dt * *col[5] + hdt * d2;
  *col[3] = *col[3] + d0;
  *col[4] = *col[4] + d1;
  *col[5] = *col[5] + d2;
}

// Four rows at a time (the AVX2 build keeps them in one register each), then two, then one.
template <int Rows>
CAIRN_WIDE_KERNEL void ApplyTransitionT(const Transition& f, double* m, int ld) {
  int i = 0;
  for (; i + 4 <= Rows; i += 4) TransitionRow<4>(f, m, ld, i);
  if constexpr (Rows % 4 >= 2) {
    TransitionRow<2>(f, m, ld, i);
    i += 2;
  }
  if constexpr (Rows % 2 == 1) TransitionRow<1>(f, m, ld, i);
}

// Jr(phi) from the rotation's half-angle sine and cosine (no further trigonometry).
Eigen::Matrix3d RightJacobianFromHalfAngle(const Eigen::Vector3d& phi, double s_half, double c_half) {
  const double theta2 = phi.squaredNorm();
  const Eigen::Matrix3d W = so3::Skew(phi);
  if (theta2 < 1e-4) {
    // Series to the terms below double precision (no cancellation, no division).
    const double t = theta2;
    const double a = 0.5 - t * (1.0 / 24.0) * (1.0 - t * (1.0 / 30.0) * (1.0 - t * (1.0 / 56.0)));
    const double b = 1.0 / 6.0 - t * (1.0 / 120.0) * (1.0 - t * (1.0 / 42.0) * (1.0 - t * (1.0 / 72.0)));
    return Eigen::Matrix3d::Identity() - a * W + b * W * W;
  }
  const double theta = std::sqrt(theta2);
  const double one_minus_cos = 2.0 * s_half * s_half;
  const double sin_theta = 2.0 * s_half * c_half;
  return Eigen::Matrix3d::Identity() - one_minus_cos / theta2 * W +
         (theta - sin_theta) / (theta2 * theta) * W * W;
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
  const Eigen::Quaterniond dq = so3::ExpQuaternionSmall(phi);
  const Eigen::Quaterniond q0 = s.q;
  const Eigen::Quaterniond q1 = so3::Normalized(q0 * dq);
  const Eigen::Matrix3d R1 = q1.toRotationMatrix();
  const Eigen::Vector3d acc_world = 0.5 * (R0 * a0 + R1 * a1) + gravity_;
  s.p += s.v * dt + 0.5 * acc_world * dt * dt;
  s.v += acc_world * dt;
  s.q = q1;

  // Error transition, linearized about the mid-interval attitude q0 Exp(phi / 2) (the geodesic
  // midpoint, from dq by the half-angle formulas) and the mean specific force.
  const double c_half = dq.w();           // cos(|phi| / 2), dq is normalized with w >= 0
  const double s_half = dq.vec().norm();  // sin(|phi| / 2)
  const double c_quarter = std::sqrt(0.5 * (1.0 + c_half));
  const Eigen::Quaterniond dq_mid(c_quarter, 0.5 / c_quarter * dq.x(), 0.5 / c_quarter * dq.y(),
                                  0.5 / c_quarter * dq.z());
  const Eigen::Matrix3d R_mid = so3::Normalized(q0 * dq_mid).toRotationMatrix();
  Transition f;
  f.dt = dt;
  f.a = 0.5 * (a0 + a1);
  f.Fva = -dt * R_mid;
  f.Ftt = dq.toRotationMatrix().transpose();
  f.Ftg = -dt * RightJacobianFromHalfAngle(phi, s_half, c_half);

  // P_core <- Phi P_core Phi^T + Q: with P_core symmetric, Y^T = P_core Phi^T and then
  // Phi P_core Phi^T = Y Phi^T. Phi leaves the bias rows alone, so Y^T is formed in place (its
  // bias columns are P's) and only the p, v, theta rows of Y Phi^T are computed; the bias rows
  // follow by symmetry and the bias block only gains its noise (P_core is kept exactly
  // symmetric).
  double* const pc = s.P.data();
  ApplyTransitionT<kCoreDim>(f, pc, kStateDim);
  Eigen::Matrix<double, 9, kCoreDim> top;  // rows p, v, theta of Y, then of Y Phi^T
  for (int c = 0; c < kCoreDim; ++c) {
    for (int i = 0; i < 9; ++i) top(i, c) = pc[i * kStateDim + c];
  }
  ApplyTransitionT<9>(f, top.data(), 9);

  const double qa = noise_.accel_noise_density * noise_.accel_noise_density;
  const double qg = noise_.gyro_noise_density * noise_.gyro_noise_density;
  const double qba = noise_.accel_random_walk * noise_.accel_random_walk;
  const double qbg = noise_.gyro_random_walk * noise_.gyro_random_walk;
  const double dt2 = dt * dt;
  top.block<3, 3>(kP, kP).diagonal().array() += qa * dt2 * dt / 3.0;
  top.block<3, 3>(kP, kV).diagonal().array() += qa * dt2 / 2.0;
  top.block<3, 3>(kV, kP).diagonal().array() += qa * dt2 / 2.0;
  top.block<3, 3>(kV, kV).diagonal().array() += qa * dt;
  top.block<3, 3>(kTheta, kTheta).diagonal().array() += qg * dt;
  s.P.topLeftCorner<9, 9>() = 0.5 * (top.leftCols<9>() + top.leftCols<9>().transpose());
  s.P.block<9, 6>(0, 9) = top.rightCols<6>();  // the bias rows hold their transpose already (Y^T's)
  s.P.block<3, 3>(kBa, kBa).diagonal().array() += qba * dt;
  s.P.block<3, 3>(kBg, kBg).diagonal().array() += qbg * dt;

  // Cross-covariance with the clones: X <- Phi X, deferred (FilterState): the step joins the
  // pending product, Pi <- Phi Pi, by its blocks (names as in CoreTransitionProduct).
  CoreTransitionProduct& pi = s.pending_transition;
  const Eigen::Matrix3d FA = f.Fva * so3::Skew(f.a);
  const Eigen::Matrix3d D = FA * pi.Tt;
  const Eigen::Matrix3d E = FA * pi.Tg;
  const double hdt = 0.5 * dt;
  pi.Pt += dt * pi.Vt + hdt * D;
  pi.Pa += dt * pi.Va + hdt * f.Fva;
  pi.Pg += dt * pi.Vg + hdt * E;
  pi.T += dt;
  pi.Vt += D;
  pi.Va += f.Fva;
  pi.Vg += E;
  pi.Tg = f.Ftt * pi.Tg + f.Ftg;
  pi.Tt = f.Ftt * pi.Tt;
  pi.identity = false;
  MarkDeferred(s);

  s.time = t1;
  s.accel = accel1;
  s.gyro = gyro1;
}

}  // namespace cairn
