#include "hal/calibration.h"

namespace cairn {

Eigen::Vector2d PinholeRadTan::Distort(const Eigen::Vector2d& u) const {
  const double x = u.x(), y = u.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d PinholeRadTan::Undistort(const Eigen::Vector2d& d) const {
  // Gauss-Newton on Distort(u) = d with the analytic Jacobian: converges in a few steps even in
  // the image corners, where plain fixed-point iteration crawls.
  Eigen::Vector2d u = d;
  for (int i = 0; i < 20; ++i) {
    const double x = u.x(), y = u.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
    const double dradial = 2.0 * k1 + 4.0 * k2 * r2;  // d(radial)/d(r2) * 2
    Eigen::Matrix2d J;
    J(0, 0) = radial + x * dradial * x + 2.0 * p1 * y + 6.0 * p2 * x;
    J(0, 1) = x * dradial * y + 2.0 * p1 * x + 2.0 * p2 * y;
    J(1, 0) = y * dradial * x + 2.0 * p1 * x + 2.0 * p2 * y;
    J(1, 1) = radial + y * dradial * y + 6.0 * p1 * y + 2.0 * p2 * x;
    const Eigen::Vector2d err = Distort(u) - d;
    u -= J.inverse() * err;
    if (err.squaredNorm() < 1e-28) break;
  }
  return u;
}

Eigen::Vector2d PinholeRadTan::Project(const Eigen::Vector3d& p_cam) const {
  const Eigen::Vector2d d = Distort(p_cam.head<2>() / p_cam.z());
  return {fx * d.x() + cx, fy * d.y() + cy};
}

}  // namespace cairn
