#include "estimation/frame_switch.h"

#include <algorithm>
#include <cmath>

#include "estimation/so3.h"

namespace cairn {

FrameTransform SwitchFrame(FilterState& s, const Eigen::Isometry3d& T_imu_body,
                           StateCovariance& J, StateCovariance& JP) {
  MaterializeCovariance(s);
  const Eigen::Matrix3d R = s.q.toRotationMatrix();
  const Eigen::Vector3d t_ib = T_imu_body.translation();
  const Eigen::Vector3d lever = R * t_ib;
  const Eigen::Vector3d p_o = s.p + lever;
  const Eigen::Matrix3d R_wb = R * T_imu_body.linear();
  const double yaw = std::atan2(R_wb(1, 0), R_wb(0, 0));
  const double pitch = std::asin(std::clamp(-R_wb(2, 0), -1.0, 1.0));
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d C = Rz.transpose();

  // Yaw error as a function of the current attitude error: dyaw = a^T (R dtheta) for the ZYX yaw
  // of the body attitude.
  const double tp = std::tan(pitch);
  const Eigen::RowVector3d y =
      Eigen::RowVector3d(tp * std::cos(yaw), tp * std::sin(yaw), 1.0) * R;
  const Eigen::Matrix3d ez = so3::Skew(Eigen::Vector3d::UnitZ());
  const Eigen::Matrix3d lever_theta = so3::Skew(lever) * R;  // d(p - p_o)/d dtheta

  J.setIdentity();
  J.block<3, 3>(kP, kP).setZero();
  J.block<3, 3>(kP, kTheta) = C * lever_theta + C * ez * lever * y;
  J.block<3, 3>(kV, kV) = C;
  J.block<3, 3>(kV, kTheta) = -C * ez * s.v * y;
  J.block<3, 3>(kTheta, kTheta) -= R.transpose() * Eigen::Vector3d::UnitZ() * y;
  for (int i = 0; i < kMaxClones; ++i) {
    CloneSlot& c = s.clones[static_cast<size_t>(i)];
    if (c.id == kNoClone) continue;
    const int ic = CloneIndex(i);
    J.block<3, 3>(ic, ic) = C;
    J.block<3, 3>(ic, kP) = -C;
    J.block<3, 3>(ic, kTheta) = C * lever_theta - C * ez * (c.p_frame_imu - p_o) * y;
    J.block<3, 3>(ic + 3, kTheta) =
        -(c.q_frame_imu.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ()) * y;
  }

  FrameTransform out;
  Eigen::Matrix<double, 6, kStateDim> G = Eigen::Matrix<double, 6, kStateDim>::Zero();
  G.block<3, 3>(0, kP).setIdentity();
  G.block<3, 3>(0, kTheta) = -lever_theta;
  G.block<3, 3>(3, kTheta) = Eigen::Vector3d::UnitZ() * y;
  const Eigen::Matrix<double, 6, kStateDim> GP = G * s.P;
  out.covariance.noalias() = GP * G.transpose();
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  out.T_old_new.linear() = Rz;
  out.T_old_new.translation() = p_o;

  JP.noalias() = J * s.P;
  s.P.noalias() = JP * J.transpose();
  s.P = 0.5 * (s.P + s.P.transpose()).eval();

  const Eigen::Quaterniond qz_inv(C);
  s.p = C * (s.p - p_o);
  s.v = C * s.v;
  s.q = (qz_inv * s.q).normalized();
  for (CloneSlot& c : s.clones) {
    if (c.id == kNoClone) continue;
    c.p_frame_imu = C * (c.p_frame_imu - p_o);
    c.q_frame_imu = (qz_inv * c.q_frame_imu).normalized();
  }
  return out;
}

}  // namespace cairn
