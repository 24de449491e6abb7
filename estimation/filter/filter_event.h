#pragma once
// One entry of the local reference filter's event log: a clone, a release or a measurement at its
// time, with the outcome of processing it. Fixed size (a variant of Eigen fixed-size members), so
// the log's ring is allocated once and copying an event never allocates.

#include <cstdint>
#include <variant>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "estimation/filter/filter_result.h"
#include "estimation/filter/filter_state.h"

namespace cairn {

// A pose clone of the IMU state at the event time.
struct CloneEvent {
  CloneId clone = kNoClone;
};

// The clone is marginalized.
struct ReleaseEvent {
  CloneId clone = kNoClone;
};

// Pose of the current clone's IMU frame in the keyframe clone's IMU frame (T_k_c), with the
// covariance of [translation; rotation (right perturbation)] in the keyframe IMU frame.
struct RelativePoseEvent {
  CloneId keyframe = kNoClone;
  CloneId current = kNoClone;
  Eigen::Vector3d t_k_c = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_k_c = Eigen::Quaterniond::Identity();
  Matrix6d covariance = Matrix6d::Zero();
};

// Body-frame x/y velocity of the body origin (wheel odometry); the vertical velocity is the
// nonholonomic constraint, added when the event is applied.
struct WheelEvent {
  Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

// IMU position in the current local frame.
struct PositionEvent {
  Eigen::Vector3d p_frame_imu = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

struct FilterEvent {
  Timestamp time;
  FilterResult result = FilterResult::kPending;
  std::variant<CloneEvent, ReleaseEvent, RelativePoseEvent, WheelEvent, PositionEvent> data;
};

}  // namespace cairn
