#pragma once
// Measurement updates of the local reference filter on a FilterState: the generic EKF update with
// error injection, and the models for relative poses between clones, body velocities (wheel
// odometry, non-holonomic constraint) and positions. All sizes are fixed; nothing allocates.

#include <Eigen/Core>

#include "estimation/filter/filter_state.h"

namespace cairn {

enum class UpdateOutcome : uint8_t { kApplied, kBadCovariance, kGated };

// Relative pose of the IMU at the `current` clone in the IMU frame of the `keyframe` clone.
struct RelativePoseMeasurement {
  int keyframe_slot = -1;
  int current_slot = -1;
  Eigen::Vector3d t_k_c = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_k_c = Eigen::Quaterniond::Identity();
  Matrix6d covariance = Matrix6d::Identity();  // [translation; rotation (right perturbation)]
};

// Applies a relative-pose measurement. `gate` > 0 rejects innovations whose squared Mahalanobis
// distance exceeds it.
UpdateOutcome ApplyRelativePoseUpdate(FilterState& s, const RelativePoseMeasurement& m, double gate);

// Covariance of the predicted relative pose between the measurement's two clones.
Matrix6d RelativePoseCovariance(const FilterState& s, const RelativePoseMeasurement& m);

// Body-frame velocity of a point fixed to the IMU at lever arm `p_imu_point` (IMU frame), rotated
// into a frame `R_imu_meas` (columns = measurement axes in IMU frame); the first `rows` axes of the
// velocity are measured with covariance `cov`.
UpdateOutcome ApplyBodyVelocityUpdate(FilterState& s, const Eigen::Matrix3d& R_imu_meas,
                                      const Eigen::Vector3d& p_imu_point,
                                      const Eigen::Vector3d& velocity, const Eigen::Matrix3d& cov,
                                      int rows);

// IMU position in the current frame.
UpdateOutcome ApplyPositionUpdate(FilterState& s, const Eigen::Vector3d& p,
                                  const Eigen::Matrix3d& cov);

// Adds an error-state correction to the nominal state (biases, pose, clones).
void InjectError(FilterState& s, const Eigen::Matrix<double, kStateDim, 1>& dx);

}  // namespace cairn
