#include "estimation/filter/frame_switch.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

// The Jacobian of the frame change is sparse: each 3-row block has at most three non-zero 3x3
// blocks. Rows are addressed in units of 3 (core p, v, theta, ba, bg, then clone p, theta).
constexpr int kRowBlocks = kStateDim / 3;

struct SparseRowBlock {
  int n = 0;  // 0: identity row block
  std::array<int, 3> col{};
  std::array<Eigen::Matrix3d, 3> m;
  void Add(int c, const Eigen::Matrix3d& v) {
    col[static_cast<size_t>(n)] = c;
    m[static_cast<size_t>(n)] = v;
    ++n;
  }
};

// out = J x for a matrix with kStateDim rows.
void ApplyRows(const std::array<SparseRowBlock, kRowBlocks>& J, const StateCovariance& x, StateCovariance& out) {
  for (int b = 0; b < kRowBlocks; ++b) {
    const SparseRowBlock& r = J[static_cast<size_t>(b)];
    if (r.n == 0) {
      out.middleRows<3>(3 * b) = x.middleRows<3>(3 * b);
      continue;
    }
    out.middleRows<3>(3 * b).noalias() = r.m[0] * x.middleRows<3>(3 * r.col[0]);
    for (int k = 1; k < r.n; ++k) {
      out.middleRows<3>(3 * b).noalias() += r.m[static_cast<size_t>(k)] * x.middleRows<3>(3 * r.col[static_cast<size_t>(k)]);
    }
  }
}

}  // namespace

FrameTransform SwitchFrame(FilterState& s, const Eigen::Isometry3d& T_imu_body,
                           StateCovariance& JP, StateCovariance& scratch) {
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

  constexpr int bp = kP / 3, bv = kV / 3, bt = kTheta / 3;
  std::array<SparseRowBlock, kRowBlocks> J{};
  J[bp].Add(bt, C * lever_theta + C * ez * lever * y);  // the position error becomes zero
  J[bv].Add(bv, C);
  J[bv].Add(bt, -C * ez * s.v * y);
  J[bt].Add(bt, Eigen::Matrix3d::Identity() - R.transpose() * Eigen::Vector3d::UnitZ() * y);
  for (int i = 0; i < kMaxClones; ++i) {
    const CloneSlot& c = s.clones[static_cast<size_t>(i)];
    if (c.id == kNoClone) continue;
    const int b = CloneIndex(i) / 3;
    J[static_cast<size_t>(b)].Add(b, C);
    J[static_cast<size_t>(b)].Add(bp, -C);
    J[static_cast<size_t>(b)].Add(bt, C * lever_theta - C * ez * (c.p_frame_imu - p_o) * y);
    J[static_cast<size_t>(b + 1)].Add(b + 1, Eigen::Matrix3d::Identity());
    J[static_cast<size_t>(b + 1)].Add(bt, -(c.q_frame_imu.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ()) * y);
  }

  FrameTransform out;
  Eigen::Matrix<double, 6, kCoreDim> G = Eigen::Matrix<double, 6, kCoreDim>::Zero();
  G.block<3, 3>(0, kP).setIdentity();
  G.block<3, 3>(0, kTheta) = -lever_theta;
  G.block<3, 3>(3, kTheta) = Eigen::Vector3d::UnitZ() * y;
  const Eigen::Matrix<double, 6, kCoreDim> GP = G * s.P.topLeftCorner<kCoreDim, kCoreDim>();
  out.covariance.noalias() = GP * G.transpose();
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  out.T_old_new.linear() = Rz;
  out.T_old_new.translation() = p_o;

  // P <- J P J^T = J (J P)^T.
  ApplyRows(J, s.P, JP);
  scratch = JP.transpose();
  ApplyRows(J, scratch, JP);
  s.P = 0.5 * (JP + JP.transpose());

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
