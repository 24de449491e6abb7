#include "estimation/filter_update.h"

#include <Eigen/Cholesky>

#include "estimation/so3.h"

namespace cairn {
namespace {

// P H^T for an H that is zero outside the core columns.
template <int M>
Eigen::Matrix<double, kStateDim, M> CorePHt(const FilterState& s, const Eigen::Matrix<double, M, kStateDim>& H) {
  return s.P.leftCols<kCoreDim>() * H.template leftCols<kCoreDim>().transpose();
}

// P H^T for an H that is zero outside two clone blocks.
Eigen::Matrix<double, kStateDim, 6> ClonePHt(const FilterState& s, const Eigen::Matrix<double, 6, kStateDim>& H,
                                             int ik, int ic) {
  Eigen::Matrix<double, kStateDim, 6> PHt = s.P.middleCols<6>(ik) * H.middleCols<6>(ik).transpose();
  PHt.noalias() += s.P.middleCols<6>(ic) * H.middleCols<6>(ic).transpose();
  return PHt;
}

// The EKF update given P H^T (computed by the caller, exploiting H's sparsity). P must be
// materialized (MaterializeCovariance) before PHt is formed.
template <int M>
UpdateOutcome KalmanUpdate(FilterState& s, const Eigen::Matrix<double, M, kStateDim>& H,
                           const Eigen::Matrix<double, kStateDim, M>& PHt,
                           const Eigen::Matrix<double, M, 1>& r,
                           const Eigen::Matrix<double, M, M>& R, double gate) {
  Eigen::Matrix<double, M, M> S = H * PHt + R;
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  if (llt.info() != Eigen::Success) return UpdateOutcome::kBadCovariance;
  if (gate > 0.0 && r.dot(llt.solve(r)) > gate) return UpdateOutcome::kGated;
  // K = P H^T S^-1, computed as (S^-1 H P)^T.
  const Eigen::Matrix<double, kStateDim, M> K = llt.solve(PHt.transpose()).transpose();
  const Eigen::Matrix<double, kStateDim, 1> dx = K * r;
  s.P.noalias() -= K * PHt.transpose();
  s.P = 0.5 * (s.P + s.P.transpose()).eval();
  InjectError(s, dx);
  return UpdateOutcome::kApplied;
}

}  // namespace

void InjectError(FilterState& s, const Eigen::Matrix<double, kStateDim, 1>& dx) {
  s.p += dx.segment<3>(kP);
  s.v += dx.segment<3>(kV);
  s.q = (s.q * so3::ExpQuaternion(dx.segment<3>(kTheta))).normalized();
  s.ba += dx.segment<3>(kBa);
  s.bg += dx.segment<3>(kBg);
  for (int i = 0; i < kMaxClones; ++i) {
    CloneSlot& c = s.clones[static_cast<size_t>(i)];
    if (c.id == kNoClone) continue;
    c.p_frame_imu += dx.segment<3>(CloneIndex(i));
    c.q_frame_imu = (c.q_frame_imu * so3::ExpQuaternion(dx.segment<3>(CloneIndex(i) + 3))).normalized();
  }
}

namespace {

// Prediction and Jacobian of a relative pose between two clones.
void RelativePoseModel(const FilterState& s, const RelativePoseMeasurement& m, Eigen::Vector3d* t_hat,
                       Eigen::Quaterniond* q_hat, Eigen::Matrix<double, 6, kStateDim>* H) {
  const CloneSlot& k = s.clones[static_cast<size_t>(m.keyframe_slot)];
  const CloneSlot& c = s.clones[static_cast<size_t>(m.current_slot)];
  const Eigen::Matrix3d Rk = k.q_frame_imu.toRotationMatrix();
  *t_hat = Rk.transpose() * (c.p_frame_imu - k.p_frame_imu);
  *q_hat = k.q_frame_imu.conjugate() * c.q_frame_imu;
  const Eigen::Matrix3d R_rel = q_hat->toRotationMatrix();
  H->setZero();
  const int ik = CloneIndex(m.keyframe_slot);
  const int ic = CloneIndex(m.current_slot);
  H->block<3, 3>(0, ik) = -Rk.transpose();
  H->block<3, 3>(0, ik + 3) = so3::Skew(*t_hat);
  H->block<3, 3>(0, ic) = Rk.transpose();
  H->block<3, 3>(3, ik + 3) = -R_rel.transpose();
  H->block<3, 3>(3, ic + 3) = Eigen::Matrix3d::Identity();
}

}  // namespace

Matrix6d RelativePoseCovariance(const FilterState& state, const RelativePoseMeasurement& m) {
  FilterState s = state;  // a copy: the deferred cross-covariance must be applied
  MaterializeCovariance(s);
  Eigen::Vector3d t_hat;
  Eigen::Quaterniond q_hat;
  Eigen::Matrix<double, 6, kStateDim> H;
  RelativePoseModel(s, m, &t_hat, &q_hat, &H);
  return H * s.P * H.transpose();
}

UpdateOutcome ApplyRelativePoseUpdate(FilterState& s, const RelativePoseMeasurement& m, double gate) {
  Eigen::Vector3d t_hat;
  Eigen::Quaterniond q_hat;
  Eigen::Matrix<double, 6, kStateDim> H;
  RelativePoseModel(s, m, &t_hat, &q_hat, &H);
  Eigen::Matrix<double, 6, 1> r;
  r.head<3>() = m.t_k_c - t_hat;
  r.tail<3>() = so3::Log(q_hat.conjugate() * m.q_k_c);
  MaterializeCovariance(s);
  const Eigen::Matrix<double, kStateDim, 6> PHt =
      ClonePHt(s, H, CloneIndex(m.keyframe_slot), CloneIndex(m.current_slot));
  return KalmanUpdate<6>(s, H, PHt, r, m.covariance, gate);
}

UpdateOutcome ApplyBodyVelocityUpdate(FilterState& s, const Eigen::Matrix3d& R_imu_meas,
                                      const Eigen::Vector3d& p_imu_point,
                                      const Eigen::Vector3d& velocity, const Eigen::Matrix3d& cov,
                                      int rows) {
  // v_meas = R_meas_imu (R^T v + w x p_imu_point), w = gyro - bg.
  const Eigen::Matrix3d R = s.q.toRotationMatrix();
  const Eigen::Matrix3d A = R_imu_meas.transpose();
  const Eigen::Vector3d w = s.gyro - s.bg;
  const Eigen::Vector3d v_imu = R.transpose() * s.v;
  const Eigen::Vector3d predicted = A * (v_imu + w.cross(p_imu_point));
  Eigen::Matrix<double, 3, kStateDim> H3 = Eigen::Matrix<double, 3, kStateDim>::Zero();
  H3.block<3, 3>(0, kV) = A * R.transpose();
  H3.block<3, 3>(0, kTheta) = A * so3::Skew(v_imu);
  H3.block<3, 3>(0, kBg) = A * so3::Skew(p_imu_point);
  const Eigen::Vector3d r3 = velocity - predicted;
  MaterializeCovariance(s);
  if (rows == 2) {
    const Eigen::Matrix<double, 2, kStateDim> H2 = H3.topRows<2>();
    return KalmanUpdate<2>(s, H2, CorePHt<2>(s, H2), r3.head<2>(), cov.topLeftCorner<2, 2>(), 0.0);
  }
  if (rows == 1) {
    const Eigen::Matrix<double, 1, kStateDim> H1 = H3.topRows<1>();
    return KalmanUpdate<1>(s, H1, CorePHt<1>(s, H1), r3.head<1>(), cov.topLeftCorner<1, 1>(), 0.0);
  }
  return KalmanUpdate<3>(s, H3, CorePHt<3>(s, H3), r3, cov, 0.0);
}

UpdateOutcome ApplyPositionUpdate(FilterState& s, const Eigen::Vector3d& p,
                                  const Eigen::Matrix3d& cov) {
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  H.block<3, 3>(0, kP).setIdentity();
  MaterializeCovariance(s);
  return KalmanUpdate<3>(s, H, CorePHt<3>(s, H), Eigen::Vector3d(p - s.p), cov, 0.0);
}

}  // namespace cairn
