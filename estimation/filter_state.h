#pragma once
// The local reference filter's complete state: nominal IMU state, pose clones in fixed slots and
// the joint error-state covariance. Everything is fixed-size so that a copy (a replay snapshot)
// never allocates. Error state: [dp dv dtheta dba dbg | clone0 (dp dtheta) | clone1 ...], attitude
// errors are right perturbations R = R_hat * Exp(dtheta).

#include <array>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hal/timestamp.h"

namespace cairn {

// Five visual-odometry keyframes plus the clones of frames whose relative pose is still in
// flight (about 250 ms at 20 Hz) and the newest one.
inline constexpr int kMaxClones = 12;
inline constexpr int kCoreDim = 15;
inline constexpr int kStateDim = kCoreDim + 6 * kMaxClones;
inline constexpr int kP = 0, kV = 3, kTheta = 6, kBa = 9, kBg = 12;
constexpr int CloneIndex(int slot) { return kCoreDim + 6 * slot; }

using CloneId = uint64_t;
inline constexpr CloneId kNoClone = 0;

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using StateCovariance = Eigen::Matrix<double, kStateDim, kStateDim>;

struct CloneSlot {
  CloneId id = kNoClone;  // kNoClone = free slot (its covariance rows/columns are zero)
  Timestamp time;
  Eigen::Vector3d p_frame_imu = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_frame_imu = Eigen::Quaterniond::Identity();
  // Creation time, then the state time of the latest relative pose that used it as keyframe:
  // when the slots are full the least recently used clone is marginalized.
  Timestamp last_used;
};

struct FilterState {
  Timestamp time;
  // IMU pose and velocity in the current local frame (gravity along -z).
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  // Raw IMU reading at `time` (interpolated when `time` lies between samples): the start point of
  // the next propagation interval.
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  std::array<CloneSlot, kMaxClones> clones{};
  StateCovariance P = StateCovariance::Zero();
  // Propagation only changes the core-clone cross-covariance by left-multiplication with the
  // transition matrix, so it is accumulated here and applied once, before anything reads it:
  // the true cross block is phi * P.topRightCorner (see MaterializeCovariance).
  Eigen::Matrix<double, kCoreDim, kCoreDim> phi = Eigen::Matrix<double, kCoreDim, kCoreDim>::Identity();
  bool cross_pending = false;
};

// Applies the accumulated transition to the core-clone cross-covariance, making P complete.
inline void MaterializeCovariance(FilterState& s) {
  if (!s.cross_pending) return;
  constexpr int kCloneDims = kStateDim - kCoreDim;
  const Eigen::Matrix<double, kCoreDim, kCloneDims> cross = s.phi * s.P.topRightCorner<kCoreDim, kCloneDims>();
  s.P.topRightCorner<kCoreDim, kCloneDims>() = cross;
  s.P.bottomLeftCorner<kCloneDims, kCoreDim>() = cross.transpose();
  s.phi.setIdentity();
  s.cross_pending = false;
}

}  // namespace cairn
