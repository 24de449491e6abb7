#include "estimation/filter/wheel_velocity.h"

#include <cmath>

#include <Eigen/Cholesky>

#include "estimation/filter/local_reference_filter.h"

namespace cairn {

bool WheelBodyVelocity(const WheelOdometrySample& sample, const WheelCalibration& calibration,
                       double lateral_sigma, BodyVelocity* out) {
  const int n = std::min<int>(sample.wheel_count, calibration.wheel_count);
  if (n < 2 || calibration.speed_noise <= 0.0 || lateral_sigma <= 0.0) return false;
  // Normal equations A^T W A x = A^T W b for x = (vx, vy, wz).
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  const double w_speed = 1.0 / (calibration.speed_noise * calibration.speed_noise);
  const double w_lat = 1.0 / (lateral_sigma * lateral_sigma);
  for (int i = 0; i < n; ++i) {
    const WheelState& wheel = sample.wheels[static_cast<size_t>(i)];
    const Eigen::Vector2d& p = calibration.p_body_wheel[static_cast<size_t>(i)];
    if (!std::isfinite(wheel.speed) || !std::isfinite(wheel.steering_angle)) return false;
    const double c = std::cos(wheel.steering_angle), s = std::sin(wheel.steering_angle);
    // Contact point velocity (vx - wz*py, vy + wz*px) along (c, s) and across (-s, c).
    const Eigen::Vector3d along(c, s, -c * p.y() + s * p.x());
    const Eigen::Vector3d across(-s, c, s * p.y() + c * p.x());
    N += w_speed * along * along.transpose() + w_lat * across * across.transpose();
    rhs += w_speed * along * wheel.speed;
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(N);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || ldlt.vectorD().minCoeff() <= 1e-12 * ldlt.vectorD().maxCoeff()) {
    return false;
  }
  const Eigen::Vector3d x = ldlt.solve(rhs);
  const Eigen::Matrix3d cov = ldlt.solve(Eigen::Matrix3d::Identity());
  if (!x.allFinite()) return false;
  out->time = sample.time;
  out->v_xy = x.head<2>();
  out->covariance = 0.5 * (cov.topLeftCorner<2, 2>() + cov.topLeftCorner<2, 2>().transpose());
  return true;
}

}  // namespace cairn
