#pragma once
// Body x/y velocity from one wheel-odometry sample: each wheel's contact point moves with
// v + w x p; its speed is measured along the wheel's rolling direction (noise speed_noise) and its
// side slip is taken as zero (noise lateral_sigma). Weighted least squares over (vx, vy, wz); the
// result's covariance is the marginal of (vx, vy).

#include "hal/calibration.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

struct BodyVelocity;

// False when the wheels do not determine the velocity (fewer than two wheels, singular geometry,
// non-finite values).
bool WheelBodyVelocity(const WheelOdometrySample& sample, const WheelCalibration& calibration,
                       double lateral_sigma, BodyVelocity* out);

}  // namespace cairn
