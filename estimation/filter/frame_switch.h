#pragma once
// Frame-of-reference switch (thesis 4.1.2): the new local frame sits at the body's current
// position with its current yaw, gravity aligned. The nominal state and the clones are expressed
// in the new frame; the error covariance is mapped with the Jacobian of that change, which
// carries the old frame's position and yaw uncertainty into the returned transform and leaves the
// body's position and yaw in the new frame without uncertainty.

#include <Eigen/Geometry>

#include "estimation/filter/filter_state.h"

namespace cairn {

struct FrameTransform {
  Eigen::Isometry3d T_old_new = Eigen::Isometry3d::Identity();
  // Of [position; rotation] with the rotation a right perturbation of T_old_new (only yaw moves,
  // so roll and pitch rows are zero).
  Matrix6d covariance = Matrix6d::Zero();
};

// `scratch` is caller-owned working memory (avoids large stack temporaries on the real-time thread).
FrameTransform SwitchFrame(FilterState& s, const Eigen::Isometry3d& T_imu_body,
                           StateCovariance& scratch_j, StateCovariance& scratch_p);

}  // namespace cairn
